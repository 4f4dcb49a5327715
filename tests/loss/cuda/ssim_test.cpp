// The CUDA SSIM against the CPU kernels: mean, map, partials and the weighted backward pass.
// Skipped where no CUDA device can be used.
#include "loss/cuda/ssim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/cuda/device.hpp"
#include "loss/ssim.hpp"
#include "support/compare.hpp"

namespace iesrgs::loss::cuda {
namespace {

using iesrgs::cuda::DeviceArray;

std::vector<float> random_values(size_t n, uint32_t seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (float& x : v) x = u(rng);
  return v;
}

// x is y plus noise, with a flat region where the window statistics nearly cancel.
void expect_same(const ImageShape& shape, bool sparse_weight) {
  SCOPED_TRACE(::testing::Message() << shape.width << "x" << shape.height << "x" << shape.channels);
  std::vector<float> y = random_values(shape.values(), 1, 0.f, 1.f);
  std::vector<float> x = y;
  const std::vector<float> noise = random_values(shape.values(), 2, -0.1f, 0.1f);
  for (size_t i = 0; i < x.size(); ++i)
    x[i] = i % shape.pixels() < shape.pixels() / 4 ? 0.5f : std::clamp(x[i] + noise[i], 0.f, 1.f);
  std::vector<float> weight = random_values(shape.pixels(), 3, 0.f, 1.f);
  if (sparse_weight)
    for (size_t p = 0; p < weight.size(); ++p)
      if (p % 97 != 0) weight[p] = 0;

  std::vector<float> map(shape.pixels()), partials(ssim_partials_size(shape));
  std::vector<float> grad(shape.values(), 0.25f);
  const double mean = ssim(x.data(), y.data(), shape, map.data(), partials.data());
  ssim_backward(x.data(), y.data(), shape, partials.data(), weight.data(), grad.data());

  const DeviceArray<float> dx(x), dy(y), dweight(weight);
  DeviceArray<float> dmap, dpartials, dgrad(std::vector<float>(shape.values(), 0.25f));
  DeviceArray<float> dmean;
  Ssim kernels;
  kernels.forward(dx.data(), dy.data(), shape, dmap.reserve(map.size()),
                  dpartials.reserve(partials.size()), dmean.reserve(1));
  kernels.backward(dx.data(), dy.data(), shape, dpartials.data(), dweight.data(), dgrad.data());

  EXPECT_NEAR(dmean.download().at(0), mean, 1e-6);
  EXPECT_LE(testing::max_abs_diff(dmap.download(), map), 1e-5f);
  EXPECT_LE(testing::relative_l2_error(dpartials.download(), partials), 1e-5);
  EXPECT_LE(testing::relative_l2_error(dgrad.download(), grad), 1e-5);
  // Without map and partials, the mean alone.
  kernels.forward(dx.data(), dy.data(), shape, nullptr, nullptr, dmean.data());
  EXPECT_NEAR(dmean.download().at(0), mean, 1e-6);
}

TEST(CudaSsim, MatchesCpuOnImagesOfOddSizes) {
  if (!iesrgs::cuda::device_available()) GTEST_SKIP() << "no CUDA device";
  expect_same({67, 45, 3}, false);
  expect_same({5, 200, 1}, true);
  expect_same({400, 300, 3}, true);
}

}  // namespace
}  // namespace iesrgs::loss::cuda
