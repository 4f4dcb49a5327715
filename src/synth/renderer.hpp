#pragma once
// A small ray tracer for the synthetic scene: exact primary hits, Lambertian shading with hard
// shadows from one directional light, antialiased by stratified supersampling.
#include <cmath>
#include <vector>

#include "io/image.hpp"
#include "synth/camera_path.hpp"
#include "synth/scene_layout.hpp"

namespace iesrgs::synth {

struct RenderSettings {
  int width = 0, height = 0;
  double camera_angle_x = kCameraAngleX;  // horizontal field of view, radians
  int grid = 4;  // samples per pixel along each axis: grid x grid jittered samples

  double focal() const { return 0.5 * width / std::tan(0.5 * camera_angle_x); }  // pixels
};

struct RenderedView {
  // Straight (not premultiplied) colour of the samples that hit something, alpha = their share,
  // so compositing over any background gives the antialiased image.
  Image rgba;
  // Row-major camera-space depth along the optical axis, averaged over the samples that hit
  // something (the expected depth a splatting renderer computes); 0 where nothing is hit.
  std::vector<float> depth;
};

// Pixel (x, y) covers [x, x+1] x [y, y+1]; the principal point is the image center.
RenderedView render_view(const SynthScene& scene, const CameraPose& pose,
                         const RenderSettings& settings);

}  // namespace iesrgs::synth
