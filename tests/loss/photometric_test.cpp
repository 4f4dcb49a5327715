#include "loss/photometric.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "loss/loss_test_support.hpp"
#include "loss/ssim.hpp"

namespace iesrgs::loss {
namespace {

using loss_testing::numeric_gradient;
using loss_testing::random_values;
using loss_testing::to_float;

TEST(L1, MeanAndMapOfAKnownPair) {
  const ImageShape shape{2, 1, 2};
  // Two pixels, channel planes one after the other.
  const std::vector<float> x{0.1f, 0.5f, 1.0f, 0.0f}, y{0.3f, 0.5f, 0.25f, 0.5f};
  EXPECT_NEAR(l1(x.data(), y.data(), shape), (0.2 + 0 + 0.75 + 0.5) / 4, 1e-7);
  std::vector<float> map(2);
  l1_map(x.data(), y.data(), shape, map.data());
  EXPECT_NEAR(map[0], 0.475f, 1e-7);
  EXPECT_NEAR(map[1], 0.25f, 1e-7);
}

TEST(L1, BackwardMatchesFiniteDifferences) {
  const ImageShape shape{6, 5, 3};
  // x and y at least 0.1 apart, so that no step crosses the kink of |x - y|.
  std::vector<double> x = random_values(shape.values(), 1), y = x;
  const std::vector<double> offset = random_values(shape.values(), 2, 0.1, 0.5);
  for (size_t i = 0; i < y.size(); ++i) y[i] += i % 2 ? offset[i] : -offset[i];
  const std::vector<double> weight = random_values(shape.pixels(), 3, -1.0, 1.0);
  const auto weighted_sum = [&](const std::vector<double>& at) {
    std::vector<double> map(shape.pixels());
    l1_map(at.data(), y.data(), shape, map.data());
    double sum = 0;
    for (size_t p = 0; p < map.size(); ++p) sum += weight[p] * map[p];
    return sum;
  };
  std::vector<double> gradient(shape.values(), 0.0);
  l1_backward(x.data(), y.data(), shape, weight.data(), gradient.data());
  loss_testing::expect_gradient_near(gradient, numeric_gradient(x, weighted_sum), 1e-6);
}

TEST(L1, GradientIsZeroWhereTheImagesAgree) {
  const ImageShape shape{1, 1, 2};
  const std::vector<float> x{0.5f, 0.5f}, y{0.5f, 0.25f}, weight{1.f};
  std::vector<float> gradient(2, 0.f);
  l1_backward(x.data(), y.data(), shape, weight.data(), gradient.data());
  EXPECT_EQ(gradient[0], 0.f);
  EXPECT_EQ(gradient[1], 0.5f);
}

TEST(Photometric, IdenticalImagesGiveZeroLossAndGradient) {
  const ImageShape shape{16, 9, 3};
  const std::vector<double> x = random_values(shape.values(), 4);
  EXPECT_NEAR(dssim(x.data(), x.data(), shape), 0.0, 1e-12);
  std::vector<double> gradient(shape.values(), 0.0);
  EXPECT_NEAR(photometric_loss(x.data(), x.data(), shape, kDssimWeight, gradient.data()), 0.0,
              1e-12);
  for (double g : gradient) EXPECT_NEAR(g, 0.0, 1e-12);
}

TEST(Photometric, MixesL1AndDssim) {
  const ImageShape shape{21, 18, 3};
  const std::vector<float> x = to_float(random_values(shape.values(), 5));
  const std::vector<float> y = to_float(random_values(shape.values(), 6));
  const double expected =
      0.8 * l1(x.data(), y.data(), shape) + 0.2 * dssim(x.data(), y.data(), shape);
  EXPECT_NEAR(photometric_loss<float>(x.data(), y.data(), shape, 0.2, nullptr), expected, 1e-6);
  std::vector<float> map(shape.pixels());
  photometric_map(x.data(), y.data(), shape, 0.2, map.data());
  EXPECT_NEAR(loss_testing::mean(std::vector<double>(map.begin(), map.end())), expected, 1e-6);
}

TEST(Photometric, GradientMatchesFiniteDifferences) {
  const ImageShape shape{12, 13, 3};
  const std::vector<double> x = random_values(shape.values(), 7, 0.0, 0.5);
  const std::vector<double> y = random_values(shape.values(), 8, 0.55, 1.0);  // no L1 kink
  std::vector<double> gradient(shape.values(), 0.0);
  photometric_loss(x.data(), y.data(), shape, kDssimWeight, gradient.data());
  const auto loss = [&](const std::vector<double>& at) {
    return photometric_loss<double>(at.data(), y.data(), shape, kDssimWeight, nullptr);
  };
  loss_testing::expect_gradient_near(gradient, numeric_gradient(x, loss), 1e-4);
}

// Weights that vanish but on a few pixels take the tiled SSIM path; it must give what the whole
// image gives.
TEST(Photometric, SparseWeightsGiveTheLossAndGradientOfTheWholeImage) {
  const ImageShape shape{80, 70, 3};
  const std::vector<double> x = random_values(shape.values(), 9, 0.0, 0.5);
  const std::vector<double> y = random_values(shape.values(), 10, 0.55, 1.0);
  std::vector<double> weight(shape.pixels(), 0.0);
  for (size_t p : {size_t(0), size_t(33 * 80 + 31), size_t(69 * 80 + 79)}) weight[p] = 0.3;
  ASSERT_LT(2 * ssim_support(weight.data(), shape).weighted.size(),
            ssim_support(weight.data(), shape).tiles);

  std::vector<double> map(shape.pixels());
  photometric_map(x.data(), y.data(), shape, kDssimWeight, map.data());
  double expected = 0;
  for (size_t p = 0; p < map.size(); ++p) expected += weight[p] * map[p];
  std::vector<double> expected_gradient(shape.values(), 0.0), partials(ssim_partials_size(shape));
  std::vector<double> l1_weight(weight), ssim_weight(weight);
  for (size_t p = 0; p < weight.size(); ++p) {
    l1_weight[p] *= 1 - kDssimWeight;
    ssim_weight[p] *= -kDssimWeight;
  }
  l1_backward(x.data(), y.data(), shape, l1_weight.data(), expected_gradient.data());
  ssim<double>(x.data(), y.data(), shape, nullptr, partials.data());
  ssim_backward(x.data(), y.data(), shape, partials.data(), ssim_weight.data(),
                expected_gradient.data());

  // A dense call on NaN images first: the sparse call, which writes its buffers only around the
  // weighted pixels, must not read what is left of it elsewhere.
  const std::vector<double> nan(shape.values(), std::numeric_limits<double>::quiet_NaN());
  const std::vector<double> uniform(shape.pixels(), 1.0);
  std::vector<double> ignored(shape.values(), 0.0);
  weighted_photometric_loss(nan.data(), nan.data(), shape, kDssimWeight, uniform.data(),
                            ignored.data());

  std::vector<double> gradient(shape.values(), 0.0);
  EXPECT_NEAR(weighted_photometric_loss(x.data(), y.data(), shape, kDssimWeight, weight.data(),
                                        gradient.data()),
              expected, 1e-12);
  for (size_t i = 0; i < gradient.size(); ++i)
    EXPECT_NEAR(gradient[i], expected_gradient[i], 1e-15) << i;
}

}  // namespace
}  // namespace iesrgs::loss
