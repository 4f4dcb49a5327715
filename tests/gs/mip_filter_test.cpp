#include "gs/mip_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace iesrgs::gs {
namespace {

// L = sum_k w_k var_k + v factor, a loss with both of the filter's outputs in it.
double loss(const double* log_scale, double filter_std) {
  const double scale[3] = {std::exp(log_scale[0]), std::exp(log_scale[1]), std::exp(log_scale[2])};
  double var[3];
  const double factor = filter3d(scale, filter_std, var);
  return 0.3 * var[0] - 0.2 * var[1] + 0.7 * var[2] + 1.5 * factor;
}

TEST(MipFilter, Filter3dBackwardIsTheDerivativeInLogScale) {
  const double log_scale[3] = {-3.0, -4.5, -2.0}, filter_std = 0.02;
  const double scale[3] = {std::exp(-3.0), std::exp(-4.5), std::exp(-2.0)};
  const double dvar[3] = {0.3, -0.2, 0.7};
  double dlog_scale[3];
  filter3d_backward(scale, filter_std, dvar, 1.5, dlog_scale);
  for (int k = 0; k < 3; ++k) {
    double plus[3] = {log_scale[0], log_scale[1], log_scale[2]}, minus[3];
    std::copy(plus, plus + 3, minus);
    plus[k] += 1e-6;
    minus[k] -= 1e-6;
    const double numeric = (loss(plus, filter_std) - loss(minus, filter_std)) / 2e-6;
    EXPECT_NEAR(dlog_scale[k], numeric, 1e-6 * (1 + std::fabs(numeric))) << "axis " << k;
  }
}

// A Gaussian shrunk until exp(log s) is 0 in floats on one axis: invisible, and its gradient
// must stay finite rather than 0 * inf.
TEST(MipFilter, Filter3dBackwardOfAnUnderflowedScaleIsFinite) {
  const float scale[3] = {0.f, 0.1f, 0.2f}, dvar[3] = {1, 1, 1};
  float var[3], dlog_scale[3];
  EXPECT_EQ(filter3d(scale, 0.05f, var), 0.f);
  filter3d_backward(scale, 0.05f, dvar, 1.f, dlog_scale);
  for (float d : dlog_scale) EXPECT_TRUE(std::isfinite(d)) << d;
}

}  // namespace
}  // namespace iesrgs::gs
