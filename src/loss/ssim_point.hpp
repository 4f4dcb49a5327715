#pragma once
// SSIM at one pixel of one channel from its window statistics, and its derivatives: shared by the
// CPU kernels (ssim.cpp) and the CUDA ones (cuda/ssim.cu).
#include <array>
#include <cmath>

#include "core/hd.hpp"
#include "loss/ssim.hpp"

namespace iesrgs::loss {

// The normalized 1-D Gaussian of the window; the 2-D window is its outer product.
inline std::array<double, kSsimWindow> ssim_window() {
  std::array<double, kSsimWindow> tap;
  double sum = 0;
  for (int k = 0; k < kSsimWindow; ++k) {
    const double d = k - kSsimWindow / 2;
    tap[k] = std::exp(-d * d / (2 * kSsimSigma * kSsimSigma));
    sum += tap[k];
  }
  for (double& t : tap) t /= sum;
  return tap;
}

// SSIM of one channel at one pixel and its derivatives with respect to the window mean, mean
// square and mean product of x (the convolutions of x, x^2 and x*y).
template <typename T>
struct SsimPoint {
  T value, d_mean, d_square, d_cross;
};

// From the window means of x and y, their spread (sum of the two variances) and covariance.
template <typename T>
IESRGS_HD_ALWAYS_INLINE SsimPoint<T> ssim_point(T mean_x, T mean_y, T spread, T cross) {
  const T c1 = T(kSsimC1), c2 = T(kSsimC2);
  const T a1 = 2 * mean_x * mean_y + c1, a2 = 2 * cross + c2;
  const T b1 = mean_x * mean_x + mean_y * mean_y + c1, b2 = spread + c2;
  const T inv_b = 1 / (b1 * b2);
  const T value = a1 * a2 * inv_b;
  // The variances are the mean square minus the squared mean, hence the b2 - b1 and a2 - a1
  // terms of the mean's derivative.
  return {value, 2 * (mean_y * (a2 - a1) - value * mean_x * (b2 - b1)) * inv_b, -value / b2,
          2 * a1 * inv_b};
}

}  // namespace iesrgs::loss
