#pragma once
// Novel camera paths for fly-around videos of a trained scene, fitted to the training cameras
// in the spirit of the ellipse trajectories of Mip-NeRF 360 and gsplat.
#include <vector>

#include "io/camera.hpp"

namespace iesrgs::pipeline {

// `frames` cameras looking at the cameras' focus point (io/camera.hpp) from the training cameras'
// mean height along the world's up (the direction across every camera's right axis: cameras are
// held level). Around a capture that goes all the way round (no gap between neighbouring cameras
// over a quarter turn), they orbit the ellipse fitted to where the cameras stand (a circle of
// cameras gives that circle); around a partial arc, they sweep along the arc the cameras cover, at
// their mean distance, and back. They have the first camera's intrinsics and are named path_0000,
// path_0001, ...
std::vector<Camera> orbit_path(const std::vector<const Camera*>& cameras, int frames);

// `frames` cameras along a smooth curve through the cameras in their given order (the capture's
// order when the images are numbered), as gsplat's and nerfstudio's interpolated paths: positions
// on a Catmull-Rom spline through the camera centres, rotations slerped between neighbours, the
// first and the last frame on the first and the last camera. For any capture, forward-facing
// ones included; first camera's intrinsics, named like orbit_path's.
std::vector<Camera> interpolated_path(const std::vector<const Camera*>& cameras, int frames);

}  // namespace iesrgs::pipeline
