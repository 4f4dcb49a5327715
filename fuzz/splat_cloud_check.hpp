#pragma once
// What every model-file harness demands of a cloud that parsed: attribute arrays sized for its
// Gaussian count and SH degree. A mismatch aborts, which libFuzzer reports as a crash.
#include <cstdlib>

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
