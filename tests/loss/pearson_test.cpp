#include "loss/pearson.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "loss/loss_test_support.hpp"

namespace iesrgs::loss {
namespace {

using loss_testing::numeric_gradient;
using loss_testing::random_values;

TEST(Pearson, LinearMapsCorrelateFully) {
  const std::vector<double> a = random_values(50, 1);
  std::vector<double> up(a.size()), down(a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    up[i] = 3 * a[i] + 100;  // far from zero, as depths are
    down[i] = 2 - 0.5 * a[i];
  }
  EXPECT_NEAR(pearson_correlation(a.data(), up.data(), nullptr, a.size()), 1.0, 1e-12);
  EXPECT_NEAR(pearson_correlation(a.data(), down.data(), nullptr, a.size()), -1.0, 1e-12);
}

TEST(Pearson, MatchesTheDefinitionOverTheMask) {
  const size_t count = 40;
  const std::vector<float> a = loss_testing::to_float(random_values(count, 2));
  const std::vector<float> b = loss_testing::to_float(random_values(count, 3));
  std::vector<uint8_t> mask(count);
  std::vector<double> sa, sb;
  for (size_t i = 0; i < count; ++i) {
    mask[i] = i % 3 != 0;
    if (!mask[i]) continue;
    sa.push_back(a[i]);
    sb.push_back(b[i]);
  }
  const double ma = loss_testing::mean(sa), mb = loss_testing::mean(sb);
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = 0; i < sa.size(); ++i) {
    ab += (sa[i] - ma) * (sb[i] - mb);
    aa += (sa[i] - ma) * (sa[i] - ma);
    bb += (sb[i] - mb) * (sb[i] - mb);
  }
  EXPECT_NEAR(pearson_correlation(a.data(), b.data(), mask.data(), count), ab / std::sqrt(aa * bb),
              1e-12);
}

TEST(Pearson, MaskedOutPixelsDoNotCount) {
  std::vector<double> a = random_values(30, 4), b = a;
  std::vector<uint8_t> mask(a.size(), 1);
  for (size_t i = 0; i < a.size(); i += 4) {
    b[i] = 1e3 * (i % 8 ? 1 : -1);  // no coverage: garbage depth
    mask[i] = 0;
  }
  EXPECT_NEAR(pearson_correlation(a.data(), b.data(), mask.data(), a.size()), 1.0, 1e-12);
}

TEST(Pearson, UndefinedCorrelationIsZeroWithoutGradient) {
  const std::vector<double> a = random_values(20, 5), flat(20, 0.5);
  const std::vector<uint8_t> none(20, 0);
  std::vector<uint8_t> one(20, 0);
  one[3] = 1;
  EXPECT_EQ(pearson_correlation(a.data(), flat.data(), nullptr, a.size()), 0.0);
  EXPECT_EQ(pearson_correlation(flat.data(), a.data(), nullptr, a.size()), 0.0);
  EXPECT_EQ(pearson_correlation(a.data(), a.data(), none.data(), a.size()), 0.0);
  EXPECT_EQ(pearson_correlation(a.data(), a.data(), one.data(), a.size()), 0.0);
  std::vector<double> grad(a.size(), 0.0);
  pearson_correlation_backward(flat.data(), a.data(), nullptr, a.size(), 1.0, grad.data());
  pearson_correlation_backward(a.data(), a.data(), none.data(), a.size(), 1.0, grad.data());
  for (double g : grad) EXPECT_EQ(g, 0.0);
}

TEST(Pearson, GradientMatchesFiniteDifferences) {
  const size_t count = 35;
  const std::vector<double> a = random_values(count, 6), b = random_values(count, 7);
  std::vector<uint8_t> mask(count, 1);
  for (size_t i = 0; i < count; i += 5) mask[i] = 0;
  std::vector<double> grad(count, 0.0);
  pearson_correlation_backward(a.data(), b.data(), mask.data(), count, -2.0, grad.data());
  const auto loss = [&](const std::vector<double>& at) {
    return -2.0 * pearson_correlation(at.data(), b.data(), mask.data(), count);
  };
  const std::vector<double> numeric = numeric_gradient(a, loss);
  loss_testing::expect_gradient_near(grad, numeric, 1e-6);
  for (size_t i = 0; i < count; i += 5) EXPECT_EQ(grad[i], 0.0);
}

TEST(Pearson, FloatGradientMatchesDouble) {
  const size_t count = 1000;
  const std::vector<double> a = random_values(count, 8, 2.0, 3.0), b = random_values(count, 9);
  std::vector<double> expected(count, 0.0);
  pearson_correlation_backward(a.data(), b.data(), nullptr, count, 1.0, expected.data());
  const std::vector<float> af = loss_testing::to_float(a), bf = loss_testing::to_float(b);
  std::vector<float> grad(count, 0.f);
  pearson_correlation_backward(af.data(), bf.data(), nullptr, count, 1.0, grad.data());
  EXPECT_LT(loss_testing::relative_max_error({grad.begin(), grad.end()}, expected), 1e-5);
}

}  // namespace
}  // namespace iesrgs::loss
