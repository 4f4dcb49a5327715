#include "io/viewer_cloud.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/math.hpp"

namespace iesrgs {

namespace {

bool all_finite(const std::vector<float>& values, size_t from, size_t count, bool exponentiated) {
  return std::all_of(values.begin() + from, values.begin() + from + count,
                     [&](float v) { return std::isfinite(exponentiated ? std::exp(v) : v); });
}

}  // namespace

SplatCloud viewer_cloud(const SplatCloud& cloud, const std::filesystem::path& path) {
  check_splat_cloud(cloud, path);  // before baking indexes the arrays
  SplatCloud baked = bake_filter_3d(cloud);
  const size_t rest = baked.size() ? baked.sh_rest.size() / baked.size() : 0;
  for (size_t i = 0; i < baked.size(); ++i) {
    const double norm = quaternion_norm(&baked.rotations[4 * i]);
    if (!all_finite(baked.positions, 3 * i, 3, false) ||
        !all_finite(baked.log_scales, 3 * i, 3, true) ||
        !all_finite(baked.sh_dc, 3 * i, 3, false) ||
        !all_finite(baked.sh_rest, rest * i, rest, false) || !std::isfinite(baked.opacity[i]) ||
        !std::isfinite(norm) || norm == 0)
      fail_file(path, fmt::format("Gaussian {} has a non-finite or degenerate parameter", i));
  }
  return baked;
}

double quaternion_norm(const float* q) {
  return std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] +
                   double(q[3]) * q[3]);
}

uint8_t to_byte(double value) {
  return uint8_t(std::clamp(std::lround(value), 0L, 255L));
}

float opacity_logit_of_byte(uint8_t byte) {
  return float(logit(std::clamp(double(byte), 0.5, 254.5) / 255));
}

}  // namespace iesrgs
