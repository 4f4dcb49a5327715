#include "loss/depth_l1.hpp"

#include <cmath>

#include "core/math.hpp"

namespace iesrgs::loss {
namespace {

// 1 where the pixel counts, else 0: arithmetic rather than a branch or a select, which GCC does
// not vectorize here.
template <typename T>
T counted_pixel(T alpha, T reference) {
  return T(alpha >= T(kDepthCoverageAlpha)) * T(reference > 0);
}

}  // namespace

template <typename T>
CoveredDepthL1 covered_depth_l1(const T* depth, const T* alpha, const T* reference, size_t count) {
  double sum = 0;
  int64_t pixels = 0;
#pragma omp parallel for simd reduction(+ : sum, pixels)
  for (int64_t i = 0; i < int64_t(count); ++i) {
    const T counted = counted_pixel(alpha[i], reference[i]);
    // Off the counted pixels alpha is replaced by 1, which keeps every lane finite.
    const T error = std::abs(depth[i] / (alpha[i] * counted + (1 - counted)) - reference[i]);
    sum += double(counted * error);
    pixels += int64_t(counted);
  }
  return {pixels > 0 ? sum / double(pixels) : 0.0, pixels};
}

template <typename T>
void covered_depth_l1_backward(const T* depth, const T* alpha, const T* reference, size_t count,
                               T scale, T* grad_depth, T* grad_alpha) {
#pragma omp parallel for simd
  for (int64_t i = 0; i < int64_t(count); ++i) {
    const T counted = counted_pixel(alpha[i], reference[i]);
    const T a = alpha[i] * counted + (1 - counted);
    // Written as autograd differentiates the quotient (torch's div backward), so that the
    // gradient is the tensor ops' to the bit; g is 0 off the counted pixels.
    const T expected = depth[i] / a;
    const T g = counted * scale * sign(expected - reference[i]);
    grad_depth[i] = g / a;
    grad_alpha[i] = -g * (expected / a);
  }
}

template CoveredDepthL1 covered_depth_l1(const float*, const float*, const float*, size_t);
template CoveredDepthL1 covered_depth_l1(const double*, const double*, const double*, size_t);
template void covered_depth_l1_backward(const float*, const float*, const float*, size_t, float,
                                        float*, float*);
template void covered_depth_l1_backward(const double*, const double*, const double*, size_t, double,
                                        double*, double*);

}  // namespace iesrgs::loss
