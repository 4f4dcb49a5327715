#pragma once
// Posed cameras for geometry tests: cameras that look at a given point.
#include <cmath>
#include <vector>

#include "io/camera.hpp"
#include "synth/camera_path.hpp"

namespace iesrgs::testing {

// A camera at `eye` looking at `target`, world +z up, posed by the synthetic scene's own look-at.
inline Camera camera_at(const Vec3& eye, const Vec3& target) {
  const auto matrix = synth::look_at(eye, target).matrix();
  double c2w[4][4];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) c2w[r][c] = matrix[r][c];
  Camera camera;
  camera.name = "train";
  camera.intrinsics = {64, 48, 50, 50, 32, 24};
  opengl_c2w_to_opencv_w2c(c2w, camera.rotation, camera.translation);
  return camera;
}

// Cameras evenly spaced on an ellipse with semi-axes a (rotated by `angle` from +x) and b, at
// height z above `target`, all looking at it.
inline std::vector<Camera> ring(double a, double b, double angle, double z, const Vec3& target,
                                int n) {
  std::vector<Camera> cameras;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n, x = a * std::cos(t), y = b * std::sin(t);
    const Vec3 offset{x * std::cos(angle) - y * std::sin(angle),
                      x * std::sin(angle) + y * std::cos(angle), z};
    cameras.push_back(camera_at(target + offset, target));
  }
  return cameras;
}

// The addresses of `cameras`, as functions over a set of cameras take them.
inline std::vector<const Camera*> pointers(const std::vector<Camera>& cameras) {
  std::vector<const Camera*> out;
  for (const Camera& camera : cameras) out.push_back(&camera);
  return out;
}

}  // namespace iesrgs::testing
