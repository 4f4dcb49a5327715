#pragma once
// Distances between arrays of results, for comparing two implementations of one kernel.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace iesrgs::testing {

// Infinite for vectors of different sizes, so that a comparison against it fails.
template <typename A, typename B>
double max_abs_diff(const std::vector<A>& a, const std::vector<B>& b) {
  if (a.size() != b.size()) return INFINITY;
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, std::abs(double(a[i]) - double(b[i])));
  return worst;
}

// |a - b| / |b| in the 2-norm over the whole array: per-element ratios are meaningless where a
// value is a sum of terms that nearly cancel. Infinite for vectors of different sizes.
inline double relative_l2_error(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return INFINITY;
  double diff = 0, norm = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    diff += double(a[i] - b[i]) * (a[i] - b[i]);
    norm += double(b[i]) * b[i];
  }
  return norm > 0 ? std::sqrt(diff / norm) : std::sqrt(diff);
}

// Whether two implementations agree to the bit: same size, same bytes.
template <typename T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

}  // namespace iesrgs::testing
