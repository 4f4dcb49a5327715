#pragma once
// Shared by the loss tests: random images, a float64 SSIM by direct 2-D convolution (the formula
// of 3DGS's utils/loss_utils.py, independent of the separable kernels), and finite differences.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "loss/image_shape.hpp"

namespace iesrgs::loss_testing {

using loss::ImageShape;

// Uniform values in [lo, hi).
inline std::vector<double> random_values(size_t count, unsigned seed, double lo = 0.0,
                                         double hi = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(lo, hi);
  std::vector<double> values(count);
  for (double& v : values) v = uniform(rng);
  return values;
}

inline std::vector<float> to_float(const std::vector<double>& values) {
  return std::vector<float>(values.begin(), values.end());
}

// Per-pixel SSIM averaged over channels (height x width), in float64 by direct 2-D convolution.
inline std::vector<double> reference_ssim_map(const std::vector<double>& x,
                                              const std::vector<double>& y,
                                              const ImageShape& shape) {
  constexpr int kRadius = 5;
  double g[2 * kRadius + 1], sum = 0;
  for (int k = -kRadius; k <= kRadius; ++k) sum += g[k + kRadius] = std::exp(-k * k / 4.5);
  for (double& v : g) v /= sum;
  const int w = shape.width, h = shape.height, channels = shape.channels;
  std::vector<double> map(shape.pixels(), 0.0);
  for (int c = 0; c < channels; ++c)
    for (int r = 0; r < h; ++r)
      for (int col = 0; col < w; ++col) {
        double mx = 0, my = 0, xx = 0, yy = 0, xy = 0;
        for (int dr = -kRadius; dr <= kRadius; ++dr)
          for (int dc = -kRadius; dc <= kRadius; ++dc) {
            const int rr = r + dr, cc = col + dc;
            if (rr < 0 || rr >= h || cc < 0 || cc >= w) continue;  // zero padding
            const double weight = g[dr + kRadius] * g[dc + kRadius];
            const size_t i = (size_t(c) * h + rr) * w + cc;
            mx += weight * x[i];
            my += weight * y[i];
            xx += weight * x[i] * x[i];
            yy += weight * y[i] * y[i];
            xy += weight * x[i] * y[i];
          }
        const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
        const double vx = xx - mx * mx, vy = yy - my * my, cov = xy - mx * my;
        const double s =
            (2 * mx * my + c1) * (2 * cov + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
        map[size_t(r) * w + col] += s / channels;
      }
  return map;
}

inline double mean(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  return sum / double(values.size());
}

// Central differences of f at x, one entry at a time.
template <typename F>
std::vector<double> numeric_gradient(std::vector<double> x, F&& f, double step = 1e-6) {
  std::vector<double> gradient(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double saved = x[i];
    x[i] = saved + step;
    const double up = f(x);
    x[i] = saved - step;
    const double down = f(x);
    x[i] = saved;
    gradient[i] = (up - down) / (2 * step);
  }
  return gradient;
}

// Each entry within `relative` of the numeric one, relative to the largest numeric entry for
// entries near zero.
inline void expect_gradient_near(const std::vector<double>& analytic,
                                 const std::vector<double>& numeric, double relative = 1e-2) {
  ASSERT_EQ(analytic.size(), numeric.size());
  double largest = 0;
  for (double v : numeric) largest = std::max(largest, std::abs(v));
  ASSERT_GT(largest, 0.0) << "the check needs a gradient that is not identically zero";
  for (size_t i = 0; i < numeric.size(); ++i)
    EXPECT_NEAR(analytic[i], numeric[i], relative * std::max(std::abs(numeric[i]), 1e-3 * largest))
        << "entry " << i;
}

// max |a - b| / max |b|: how float results compare with double ones, whose cancellation noise
// is relative to the largest entries rather than to each entry.
inline double relative_max_error(const std::vector<double>& a, const std::vector<double>& b) {
  double error = 0, largest = 0;
  for (size_t i = 0; i < b.size(); ++i) {
    error = std::max(error, std::abs(a[i] - b[i]));
    largest = std::max(largest, std::abs(b[i]));
  }
  return error / largest;
}

}  // namespace iesrgs::loss_testing
