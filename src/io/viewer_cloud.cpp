#include "io/viewer_cloud.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "core/math.hpp"

namespace iesrgs {

namespace {

bool values_are_finite(const std::vector<float>& values, size_t from, size_t count,
                       bool exponentiated) {
  return std::all_of(values.begin() + from, values.begin() + from + count,
                     [&](float v) { return std::isfinite(exponentiated ? std::exp(v) : v); });
}

// Why Gaussian i of `cloud` cannot be drawn, or nullptr when it can.
const char* undrawable(const SplatCloud& cloud, size_t i) {
  const size_t rest = cloud.sh_rest.size() / cloud.size();
  if (!values_are_finite(cloud.positions, 3 * i, 3, false)) return "a non-finite position";
  if (!values_are_finite(cloud.log_scales, 3 * i, 3, true))
    return "a scale that is no finite float once exponentiated";
  if (!values_are_finite(cloud.sh_dc, 3 * i, 3, false) ||
      !values_are_finite(cloud.sh_rest, rest * i, rest, false))
    return "a non-finite colour";
  if (!std::isfinite(cloud.opacity[i])) return "a non-finite opacity";
  const double norm = quaternion_norm(&cloud.rotations[4 * i]);
  if (!std::isfinite(norm) || norm == 0) return "a zero or non-finite rotation";
  return nullptr;
}

// The Gaussians `keep` of `cloud`, in that order.
SplatCloud select(const SplatCloud& cloud, const std::vector<size_t>& keep) {
  SplatCloud out = cloud;
  const size_t n = cloud.size();
  for (auto [from, to] : {std::pair{&cloud.positions, &out.positions},
                          {&cloud.sh_dc, &out.sh_dc},
                          {&cloud.sh_rest, &out.sh_rest},
                          {&cloud.opacity, &out.opacity},
                          {&cloud.log_scales, &out.log_scales},
                          {&cloud.rotations, &out.rotations},
                          {&cloud.filter_3d, &out.filter_3d}}) {
    const size_t stride = from->size() / n;
    to->clear();
    for (size_t i : keep)
      to->insert(to->end(), from->begin() + i * stride, from->begin() + (i + 1) * stride);
  }
  return out;
}

}  // namespace

SplatCloud viewer_cloud(const SplatCloud& cloud, const std::filesystem::path& path) {
  check_splat_cloud(cloud, path);  // before baking indexes the arrays
  const SplatCloud baked = bake_filter_3d(cloud);
  std::vector<size_t> keep;
  std::string first_left_out;
  for (size_t i = 0; i < baked.size(); ++i) {
    if (const char* reason = undrawable(baked, i)) {
      if (first_left_out.empty()) first_left_out = fmt::format("Gaussian {} has {}", i, reason);
    } else {
      keep.push_back(i);
    }
  }
  if (keep.size() == baked.size()) return baked;
  if (keep.empty())
    fail_file(path, fmt::format("not written: no Gaussian of the model can be drawn ({}, and so "
                                "have all the others)",
                                first_left_out));
  // As gsplat's export does; renders cull such Gaussians too.
  spdlog::warn("{}: left out {} of the model's {} Gaussians, which no viewer can draw ({})",
               path.string(), baked.size() - keep.size(), baked.size(), first_left_out);
  return select(baked, keep);
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
