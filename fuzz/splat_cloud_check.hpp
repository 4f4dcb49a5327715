#pragma once
// What the model-file harnesses demand of a cloud that parsed: attribute arrays sized for its
// Gaussian count and SH degree, and, from the formats that store activated values, finite values
// and unit quaternions. A violation aborts, which libFuzzer reports as a crash.
#include <cmath>
#include <cstdlib>
#include <vector>

#include "io/ply.hpp"

inline void abort_unless_consistent(const iesrgs::SplatCloud& cloud) {
  const size_t rest = size_t((cloud.sh_degree + 1) * (cloud.sh_degree + 1) - 1);
  const size_t n = cloud.size();
  if (cloud.positions.size() != 3 * n || cloud.sh_dc.size() != 3 * n ||
      cloud.sh_rest.size() != 3 * rest * n || cloud.opacity.size() != n ||
      cloud.log_scales.size() != 3 * n || cloud.rotations.size() != 4 * n ||
      (cloud.has_filter_3d() && cloud.filter_3d.size() != n))
    std::abort();
}

inline void abort_unless_finite_with_unit_rotations(const iesrgs::SplatCloud& cloud) {
  for (const auto* values : {&cloud.positions, &cloud.sh_dc, &cloud.sh_rest, &cloud.opacity,
                             &cloud.log_scales, &cloud.rotations})
    for (float v : *values)
      if (!std::isfinite(v)) std::abort();
  const std::vector<float>& q = cloud.rotations;
  for (size_t i = 0; i + 4 <= q.size(); i += 4) {
    const double norm = std::sqrt(double(q[i]) * q[i] + double(q[i + 1]) * q[i + 1] +
                                  double(q[i + 2]) * q[i + 2] + double(q[i + 3]) * q[i + 3]);
    if (!(std::fabs(norm - 1) < 1e-3)) std::abort();
  }
}
