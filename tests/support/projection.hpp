#pragma once
// Where a camera sees a world point, written out independently of the renderer's projection.
#include <utility>

#include "io/camera.hpp"

namespace iesrgs::testing {

// Pixel coordinates of a world point (pixel centers at +0.5).
inline std::pair<double, double> project(const Camera& camera, const Vec3& world) {
  const Vec3 p = camera.rotation * world + camera.translation;
  const Intrinsics& k = camera.intrinsics;
  return {k.fx * p.x / p.z + k.cx, k.fy * p.y / p.z + k.cy};
}

}  // namespace iesrgs::testing
