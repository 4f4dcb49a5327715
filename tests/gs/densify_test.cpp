#include "gs/densify.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"

namespace iesrgs::gs {
namespace {

using torch::Tensor;

constexpr double kExtent = 10;  // clone below max scale 0.1, split above; world prune above 1

// Gaussian i has mean (i, 0, 0), isotropic scale scales[i], opacity opacities[i], and SH and
// rotation values that identify it.
GaussianModel tiny_model(const std::vector<float>& scales, const std::vector<float>& opacities) {
  const int64_t n = int64_t(scales.size());
  const Tensor index = torch::arange(n, torch::kFloat32);
  const Tensor opacity = torch::tensor(opacities);
  GaussianModel m;
  m.set_params(
      {torch::stack({index, torch::zeros({n}), torch::zeros({n})}, 1),
       index.view({n, 1, 1}).expand({n, 1, 3}) + 0.5,
       index.view({n, 1, 1}).expand({n, 15, 3}) - 0.5, torch::log(opacity / (1 - opacity)),
       torch::log(torch::tensor(scales)).unsqueeze(1).repeat({1, 3}),
       torch::stack({torch::ones({n}), index * 0.1, torch::zeros({n}), torch::zeros({n})}, 1)});
  m.filter_3d = index * 0.01;
  return m;
}

// A view's statistics: screen-space gradients of norm grad_norms[i], and absolute ones (AbsGS's)
// of twice that norm, so that which of the two is read shows.
ViewStatistics view(const std::vector<float>& grad_norms, const std::vector<int>& radii) {
  const Tensor g = torch::tensor(grad_norms);
  return {torch::stack({g * 0.6, g * 0.8}, 1), torch::stack({g * 1.2, g * 1.6}, 1),
          torch::tensor(radii, torch::kInt32)};
}

// An optimizer whose moments are all non-zero, so that their movement with the rows shows; the
// parameters are put back after its step.
GaussianOptimizer stepped_optimizer(GaussianModel& m) {
  std::array<Tensor, kParamCount> before;
  for (int p = 0; p < kParamCount; ++p) {
    before[p] = m.param(Param(p)).detach().clone();
    m.param(Param(p)).mutable_grad() = torch::ones_like(before[p]);
  }
  GaussianOptimizer opt(m, {}, kExtent);
  opt.step(m);
  m.set_params(before);
  return opt;
}

TEST(Densify, AccumulatesEveryViewWhereTheGaussianIsDrawn) {
  DensifyStats stats = DensifyStats::zeros(3);
  stats.accumulate({view({1, 2, 3}, {5, 0, 2}), view({10, 20, 30}, {0, 4, 7})});
  EXPECT_TRUE(torch::allclose(stats.grad_sum, torch::tensor({1.f, 20.f, 33.f})));
  EXPECT_TRUE(torch::allclose(stats.abs_grad_sum, torch::tensor({2.f, 40.f, 66.f})));
  EXPECT_TRUE(torch::equal(stats.count, torch::tensor({1.f, 1.f, 2.f})));
  EXPECT_TRUE(torch::equal(stats.max_radii, torch::tensor({5.f, 4.f, 7.f})));
  EXPECT_THROW(stats.accumulate({view({1, 2}, {1, 1})}), Error);
}

TEST(Densify, ClonesSmallSplitsLargePrunesTransparent) {
  torch::manual_seed(0);
  // 0: small (just under 0.01 x extent), high gradient -> clone; 1: large (just over), high
  // gradient -> split; 2: small, low gradient, just over the 0.005 opacity floor -> kept;
  // 3: just under it -> pruned; 4: high gradient but only on average below threshold.
  GaussianModel m =
      tiny_model({0.09f, 0.11f, 0.05f, 0.05f, 0.05f}, {0.5f, 0.6f, 0.006f, 0.004f, 0.5f});
  GaussianOptimizer opt = stepped_optimizer(m);
  const Tensor dc_moment_of_2 = opt.moments(Param::ShDc).first[2].clone();
  DensifyStats stats = DensifyStats::zeros(5);
  stats.accumulate({view({3e-4f, 3e-4f, 1e-4f, 0, 3e-4f}, {1, 1, 1, 1, 1}),
                    view({3e-4f, 2e-4f, 1e-4f, 0, 0}, {1, 1, 1, 1, 1})});
  const DensifyCounts counts = densify_and_prune(m, opt, stats, DensifyOptions{}, kExtent);
  EXPECT_EQ(counts.cloned, 1);
  EXPECT_EQ(counts.split, 1);
  EXPECT_EQ(counts.pruned, 1);

  // Rows: originals 0, 2, 4, the clone of 0, then the two children of 1.
  ASSERT_EQ(m.size(), 6);
  EXPECT_TRUE(
      torch::equal(m.means.select(1, 0).narrow(0, 0, 4), torch::tensor({0.f, 2.f, 4.f, 0.f})));
  for (int p = 0; p < kParamCount; ++p)
    EXPECT_TRUE(torch::equal(m.param(Param(p))[3], m.param(Param(p))[0])) << p;
  for (int child : {4, 5}) {
    EXPECT_NEAR(m.log_scales[child][0].item<float>(), std::log(0.11f / 1.6f), 1e-6);
    EXPECT_TRUE(torch::equal(m.quats[child], torch::tensor({1.f, 0.1f, 0.f, 0.f})));
    EXPECT_NEAR(m.opacity_logits[child].item<float>(), std::log(0.6f / 0.4f), 1e-6);
    EXPECT_TRUE(torch::equal(m.sh_rest[child], torch::full({15, 3}, 0.5f)));
    EXPECT_NEAR(m.filter_3d[child].item<float>(), 0.01f, 1e-7);
    const float offset = (m.means[child] - torch::tensor({1.f, 0.f, 0.f})).norm().item<float>();
    EXPECT_GT(offset, 0.f);
    EXPECT_LT(offset, 5 * 0.11f * std::sqrt(3.f));
  }
  EXPECT_FALSE(torch::equal(m.means[4], m.means[5]));

  // Moments follow their rows; new rows start from zero.
  EXPECT_TRUE(torch::equal(opt.moments(Param::ShDc).first[1], dc_moment_of_2));
  for (int p = 0; p < kParamCount; ++p) {
    const AdamMoments& mom = opt.moments(Param(p));
    ASSERT_EQ(mom.first.size(0), 6);
    EXPECT_GT(mom.second.narrow(0, 0, 3).abs().min().item<float>(), 0.f) << p;
    EXPECT_EQ(mom.first.narrow(0, 3, 3).abs().max().item<float>(), 0.f) << p;
    EXPECT_EQ(mom.second.narrow(0, 3, 3).abs().max().item<float>(), 0.f) << p;
  }
  EXPECT_EQ(stats.count.size(0), 6);
  EXPECT_EQ(stats.grad_sum.abs().sum().item<float>(), 0.f);
  EXPECT_TRUE(m.means.requires_grad());
}

TEST(Densify, SplitSamplesFollowTheRotatedShape) {
  torch::manual_seed(1);
  const int n = 4000;
  GaussianModel m = tiny_model(std::vector<float>(n, 1.f), std::vector<float>(n, 0.5f));
  m.set_param(Param::Means, torch::zeros({n, 3}));
  m.set_param(Param::LogScales, torch::log(torch::tensor({1.f, 0.1f, 0.01f})).repeat({n, 1}));
  // 90 degrees about z: the long local x axis becomes world y.
  const float h = std::sqrt(0.5f);
  m.set_param(Param::Quats, torch::tensor({h, 0.f, 0.f, h}).repeat({n, 1}));
  GaussianOptimizer opt(m, {}, kExtent);
  DensifyStats stats = DensifyStats::zeros(n);
  stats.accumulate({view(std::vector<float>(n, 1.f), std::vector<int>(n, 1))});
  densify_and_prune(m, opt, stats, DensifyOptions{}, kExtent);
  ASSERT_EQ(m.size(), 2 * n);
  const Tensor spread = m.means.std(0);
  EXPECT_NEAR(spread[0].item<float>(), 0.1f, 0.01f);
  EXPECT_NEAR(spread[1].item<float>(), 1.f, 0.05f);
  EXPECT_NEAR(spread[2].item<float>(), 0.01f, 0.001f);
}

// A needle whose thin axis has shrunk until exp(log s) is 0 in floats still splits into children
// with finite log scales, 1/1.6 of the parent's.
TEST(Densify, SplitChildrenOfANeedleKeepFiniteLogScales) {
  GaussianModel m = tiny_model({1.f}, {0.5f});
  m.set_param(Param::LogScales, torch::tensor({{-120.f, 0.f, 0.f}}));
  GaussianOptimizer opt(m, {}, kExtent);
  DensifyStats stats = DensifyStats::zeros(1);
  stats.accumulate({view({1.f}, {1})});
  EXPECT_EQ(densify_and_prune(m, opt, stats, DensifyOptions{}, kExtent).split, 1);
  ASSERT_EQ(m.size(), 2);
  const float shrink = std::log(1.6f);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(m.log_scales[i][0].item<float>(), -120.f - shrink, 1e-4);
    EXPECT_NEAR(m.log_scales[i][1].item<float>(), -shrink, 1e-6);
  }
  EXPECT_TRUE(torch::isfinite(m.means).all().item<bool>());
}

TEST(Densify, AbsoluteGradientsCanDriveDensification) {
  GaussianModel m = tiny_model({0.05f}, {0.5f});
  GaussianOptimizer opt(m, {}, kExtent);
  DensifyStats stats = DensifyStats::zeros(1);
  // Norm of the plain gradient 1.5e-4, under the 2e-4 threshold; of the absolute one 3e-4, over.
  stats.accumulate({view({1.5e-4f}, {1})});
  DensifyOptions options;
  EXPECT_EQ(densify_and_prune(m, opt, stats, options, kExtent).cloned, 0);
  ASSERT_EQ(m.size(), 1);
  stats.accumulate({view({1.5e-4f}, {1})});  // the same view again: densifying zeroed the sums
  options.source = GradientSource::Absolute;
  EXPECT_EQ(densify_and_prune(m, opt, stats, options, kExtent).cloned, 1);
}

// Under max_gaussians the Gaussians of the largest gradient grow first, and the rest wait.
TEST(Densify, MaxGaussiansGrowsTheLargestGradientsFirst) {
  // 0 and 2 small (clones), 1 large (split); gradients 3e-4, 5e-4, 4e-4, all over the threshold.
  GaussianModel m = tiny_model({0.05f, 0.5f, 0.05f}, {0.5f, 0.5f, 0.5f});
  GaussianOptimizer opt(m, {}, kExtent);
  DensifyStats stats = DensifyStats::zeros(3);
  stats.accumulate({view({3e-4f, 5e-4f, 4e-4f}, {1, 1, 1})});
  DensifyOptions options;
  options.max_gaussians = 5;
  const DensifyCounts counts = densify_and_prune(m, opt, stats, options, kExtent);
  EXPECT_EQ(counts.split, 1);
  EXPECT_EQ(counts.cloned, 1);
  EXPECT_EQ(counts.held_back, 1);
  ASSERT_EQ(m.size(), 5);
  // Rows: originals 0 and 2, the clone of 2, the two children of 1.
  EXPECT_TRUE(torch::equal(m.means.select(1, 0).narrow(0, 0, 3), torch::tensor({0.f, 2.f, 2.f})));

  stats.accumulate({view(std::vector<float>(5, 1.f), std::vector<int>(5, 1))});
  const DensifyCounts full = densify_and_prune(m, opt, stats, options, kExtent);
  EXPECT_EQ(full.cloned + full.split, 0);
  EXPECT_EQ(full.held_back, 5);
  EXPECT_EQ(m.size(), 5);
}

TEST(Densify, PrunesOversizedGaussiansOnlyWhenEnabled) {
  // 0: fine; 1: 30 px on screen; 2: world scale 2 > 0.1 * extent (and large, low gradient).
  GaussianModel m = tiny_model({0.05f, 0.05f, 2.f}, {0.5f, 0.5f, 0.5f});
  GaussianOptimizer opt(m, {}, kExtent);
  DensifyStats stats = DensifyStats::zeros(3);
  stats.accumulate({view({0, 0, 0}, {5, 30, 5})});
  DensifyOptions options;
  EXPECT_EQ(densify_and_prune(m, opt, stats, options, kExtent).pruned, 0);
  stats.accumulate({view({0, 0, 0}, {5, 30, 5})});
  options.max_world_size = 0.1;
  EXPECT_EQ(densify_and_prune(m, opt, stats, options, kExtent).pruned, 1);
  ASSERT_EQ(m.size(), 2);
  EXPECT_EQ(m.means[1][0].item<float>(), 1.f);  // the 30-pixel one stays
  stats = DensifyStats::zeros(2);
  stats.accumulate({view({0, 0}, {5, 30})});
  options.max_screen_size = 20;
  EXPECT_EQ(densify_and_prune(m, opt, stats, options, kExtent).pruned, 1);
  ASSERT_EQ(m.size(), 1);
  EXPECT_EQ(m.means[0][0].item<float>(), 0.f);
}

TEST(Densify, OpacityResetCapsEffectiveOpacityAndZeroesItsMoments) {
  GaussianModel m = tiny_model({0.05f, 0.05f, 0.05f}, {0.5f, 0.005f, 0.5f});
  m.filter_3d =
      torch::tensor({0.f, 0.f, 0.05f});  // halves the volume ratio per axis: gain 1/(2 sqrt 2)
  GaussianOptimizer opt = stepped_optimizer(m);
  reset_opacity(m, opt);
  const Tensor opacity = torch::sigmoid(m.opacity_logits);
  EXPECT_NEAR(opacity[0].item<float>(), 0.01f, 1e-7);
  EXPECT_NEAR(opacity[1].item<float>(), 0.005f, 1e-7);
  EXPECT_NEAR(opacity[2].item<float>() / (2 * std::sqrt(2.f)), 0.01f, 1e-7);
  EXPECT_EQ(opt.moments(Param::OpacityLogits).first.abs().sum().item<float>(), 0.f);
  EXPECT_EQ(opt.moments(Param::OpacityLogits).second.abs().sum().item<float>(), 0.f);
  EXPECT_GT(opt.moments(Param::Means).first.abs().sum().item<float>(), 0.f);
  EXPECT_TRUE(m.opacity_logits.requires_grad());
}

// A Gaussian shrunk far below its 3D filter (scale 1e-13 per axis) has a gain that underflows
// to 0 in floats; its cap 0.01 / gain must not become 0 / 0.
TEST(Densify, OpacityResetOfGaussiansFlattenedBelowTheirFilterStaysFinite) {
  GaussianModel m = tiny_model({1e-13f, 1e-13f, 0.05f}, {0.5f, 0.999f, 0.5f});
  m.filter_3d = torch::tensor({0.05f, 0.05f, 0.05f});
  const Tensor before = m.opacity_logits.detach().clone();
  GaussianOptimizer opt = stepped_optimizer(m);
  reset_opacity(m, opt);
  EXPECT_TRUE(torch::isfinite(m.opacity_logits).all().item<bool>()) << m.opacity_logits;
  // Drawn at opacity * gain, far below 0.01: the cap does not bind and nothing changes.
  EXPECT_EQ(m.opacity_logits[0].item<float>(), before[0].item<float>());
  EXPECT_EQ(m.opacity_logits[1].item<float>(), before[1].item<float>());
  EXPECT_NEAR(torch::sigmoid(m.opacity_logits[2]).item<float>() / (2 * std::sqrt(2.f)), 0.01f,
              1e-7);
}

}  // namespace
}  // namespace iesrgs::gs
