#include "gs/filter3d.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "gs/mip_filter.hpp"

namespace iesrgs::gs {

namespace {

constexpr double kFrameMargin = 0.15;  // fraction of the image size on each side

// Camera z of `mean` if the camera sees it, infinity otherwise.
double visible_depth(const Camera& camera, const Vec3& mean) {
  const Vec3 p = camera.rotation * mean + camera.translation;
  if (p.z <= kNearPlane) return std::numeric_limits<double>::infinity();
  const Intrinsics& k = camera.intrinsics;
  const double u = k.fx * p.x / p.z + k.cx, v = k.fy * p.y / p.z + k.cy;
  const bool inside = u >= -kFrameMargin * k.width && u <= (1 + kFrameMargin) * k.width &&
                      v >= -kFrameMargin * k.height && v <= (1 + kFrameMargin) * k.height;
  return inside ? p.z : std::numeric_limits<double>::infinity();
}

}  // namespace

std::vector<float> filter3d_std(const float* means, int count, const std::vector<Camera>& cameras) {
  if (cameras.empty()) fail("3D filter: no training cameras");
  double focal = 0;
  for (const Camera& c : cameras) focal = std::max({focal, c.intrinsics.fx, c.intrinsics.fy});
  std::vector<double> depth(size_t(std::max(count, 0)));
#pragma omp parallel for schedule(static)
  for (int i = 0; i < count; ++i) {
    const Vec3 mean{means[3 * i], means[3 * i + 1], means[3 * i + 2]};
    double nearest = std::numeric_limits<double>::infinity();
    for (const Camera& c : cameras) nearest = std::min(nearest, visible_depth(c, mean));
    depth[i] = nearest;
  }
  double farthest_seen = 0;
  for (double d : depth)
    if (std::isfinite(d)) farthest_seen = std::max(farthest_seen, d);
  std::vector<float> std_dev(depth.size());
  for (size_t i = 0; i < depth.size(); ++i) {
    const double d = std::isfinite(depth[i]) ? depth[i] : farthest_seen;
    std_dev[i] = float(filter3d_std_at(d, focal));
  }
  return std_dev;
}

}  // namespace iesrgs::gs
