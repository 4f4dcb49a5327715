#include "loss/pearson.hpp"

#include <cmath>
#include <cstdint>

namespace iesrgs::loss {
namespace {

// Sums in double over the masked entries, centered in a second pass so that maps with a large
// offset (depths far from the camera) keep their precision.
struct Moments {
  double mean_a = 0, mean_b = 0;
  double aa = 0, bb = 0, ab = 0;  // centered sums of products

  bool defined() const { return aa > 0 && bb > 0; }
  double correlation() const { return defined() ? ab / std::sqrt(aa * bb) : 0.0; }
};

bool selected(const uint8_t* mask, size_t i) {
  return !mask || mask[i] != 0;
}

template <typename T>
Moments masked_moments(const T* a, const T* b, const uint8_t* mask, size_t count) {
  double sum_a = 0, sum_b = 0;
  int64_t n = 0;
#pragma omp parallel for reduction(+ : sum_a, sum_b, n)
  for (int64_t i = 0; i < int64_t(count); ++i) {
    if (!selected(mask, i)) continue;
    sum_a += a[i];
    sum_b += b[i];
    ++n;
  }
  Moments m;
  if (n < 2) return m;
  m.mean_a = sum_a / n;
  m.mean_b = sum_b / n;
  const double mean_a = m.mean_a, mean_b = m.mean_b;
  double aa = 0, bb = 0, ab = 0;
#pragma omp parallel for reduction(+ : aa, bb, ab)
  for (int64_t i = 0; i < int64_t(count); ++i) {
    if (!selected(mask, i)) continue;
    const double da = a[i] - mean_a, db = b[i] - mean_b;
    aa += da * da;
    bb += db * db;
    ab += da * db;
  }
  m.aa = aa;
  m.bb = bb;
  m.ab = ab;
  return m;
}

}  // namespace

template <typename T>
double pearson_correlation(const T* a, const T* b, const uint8_t* mask, size_t count) {
  return masked_moments(a, b, mask, count).correlation();
}

// d corr / d a_i = db_i / sqrt(aa bb) - corr da_i / aa; the means' own dependence on a_i drops
// out because the centered values sum to zero.
template <typename T>
void pearson_correlation_backward(const T* a, const T* b, const uint8_t* mask, size_t count,
                                  double scale, T* grad_a) {
  const Moments m = masked_moments(a, b, mask, count);
  if (!m.defined()) return;
  const double along_b = scale / std::sqrt(m.aa * m.bb);
  const double along_a = scale * m.correlation() / m.aa;
#pragma omp parallel for
  for (int64_t i = 0; i < int64_t(count); ++i) {
    if (!selected(mask, i)) continue;
    grad_a[i] += T(along_b * (b[i] - m.mean_b) - along_a * (a[i] - m.mean_a));
  }
}

template double pearson_correlation(const float*, const float*, const uint8_t*, size_t);
template double pearson_correlation(const double*, const double*, const uint8_t*, size_t);
template void pearson_correlation_backward(const float*, const float*, const uint8_t*, size_t,
                                           double, float*);
template void pearson_correlation_backward(const double*, const double*, const uint8_t*, size_t,
                                           double, double*);

}  // namespace iesrgs::loss
