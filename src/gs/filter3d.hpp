#pragma once
// Mip-Splatting's 3D smoothing filter size per Gaussian, from the training cameras: the highest
// sampling rate any camera sees the Gaussian at bounds the frequencies it may hold.
#include <vector>

#include "io/camera.hpp"

namespace iesrgs::gs {

// For each of the `count` means (row-major (N, 3)): over the cameras that see it in front
// (z > 0.2) and inside the frame widened by 15% on each side, the smallest camera z; then
// std = z_min / f_max * sqrt(0.2), f_max the largest focal length of all cameras. Means no camera
// sees get the largest z_min of the others (all zero when none is seen). Throws Error when
// there are no cameras.
std::vector<float> filter3d_std(const float* means, int count, const std::vector<Camera>& cameras);

}  // namespace iesrgs::gs
