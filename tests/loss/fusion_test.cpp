#include "loss/fusion.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "core/error.hpp"
#include "loss/autograd.hpp"
#include "loss/texture_fusion.hpp"
#include "support/expect_error.hpp"

namespace iesrgs::loss {
namespace {

constexpr int64_t kHeight = 12, kWidth = 14;

torch::Tensor random_image(uint64_t seed, double low = 0.2, double high = 0.9) {
  torch::manual_seed(seed);
  return low + (high - low) * torch::rand({3, kHeight, kWidth});
}

// A render whose depth and alpha are known: expected depth `depth` where alpha is 1, nothing drawn
// (alpha 0) in the left columns.
raster::RenderOutput render_with_depth(const torch::Tensor& depth, int uncovered_columns) {
  raster::RenderOutput render;
  render.image = random_image(7).requires_grad_();
  torch::Tensor alpha = torch::ones({kHeight, kWidth});
  alpha.narrow(1, 0, uncovered_columns).zero_();
  render.alpha = alpha;
  render.depth = (depth * alpha).requires_grad_();
  return render;
}

// Targets with an external image only, for the depth-term tests to add their references to.
FusionTargets external_targets(uint64_t seed) {
  FusionTargets targets;
  targets.external_image = random_image(seed);
  targets.internal_share = torch::zeros({kHeight, kWidth});
  return targets;
}

// Every test draws from one seed, so that what it draws does not depend on the tests before it.
class FusionLoss : public ::testing::Test {
 protected:
  void SetUp() override { torch::manual_seed(11); }
};

const FusionWeights kDepthWeights{TextureGuidance::External, 0.2, 1e-3, 1e-4};

TEST_F(FusionLoss, ExternalTextureIsThePhotometricLossAgainstE) {
  raster::RenderOutput render;
  render.image = random_image(1).requires_grad_();
  FusionTargets targets;
  targets.external_image = random_image(2);
  targets.internal_share = internal_share(TextureGuidance::External, {}, targets.external_image, 0);
  const FusionWeights weights{TextureGuidance::External, 0.2, 0, 0};
  const torch::Tensor loss = fusion_loss(render, targets, weights).total;
  loss.backward();
  const torch::Tensor grad = render.image.grad().clone();

  render.image.mutable_grad() = torch::Tensor();
  const torch::Tensor expected =
      0.8 * (render.image - targets.external_image).abs().mean() +
      0.2 * (1 - ssim_autograd(render.image, targets.external_image).mean);
  expected.backward();
  EXPECT_NEAR(loss.item<double>(), expected.item<double>(), 1e-6);
  EXPECT_TRUE(torch::allclose(grad, render.image.grad(), 1e-5, 1e-7));
}

TEST_F(FusionLoss, MaskedShareIsTheDiscrepancyMaskAndOthersAreConstant) {
  const torch::Tensor internal = random_image(3), external = random_image(4);
  const torch::Tensor d = discrepancy(internal, external);
  const torch::Tensor expected_d = ((internal - external).abs() / (internal + 1e-6)).mean(0);
  EXPECT_TRUE(torch::allclose(d, expected_d, 1e-5, 1e-6));
  const torch::Tensor mask = internal_share(TextureGuidance::Masked, internal, external, 0.3);
  EXPECT_TRUE(torch::equal(mask, (expected_d >= 0.3).to(torch::kFloat)));
  EXPECT_GT(mask.sum().item<double>(), 0);
  EXPECT_LT(mask.sum().item<double>(), double(kHeight * kWidth));
  EXPECT_TRUE(torch::all(internal_share(TextureGuidance::Average, internal, external, 0) == 0.5)
                  .item<bool>());
  EXPECT_TRUE(torch::all(internal_share(TextureGuidance::Internal, internal, external, 0) == 1)
                  .item<bool>());
}

TEST_F(FusionLoss, DepthTermsVanishForMatchingGeometryAndIgnoreUncoveredPixels) {
  const torch::Tensor depth = 1 + torch::rand({kHeight, kWidth});
  raster::RenderOutput render = render_with_depth(depth, 3);
  FusionTargets targets = external_targets(5);
  targets.internal_depth = depth.clone();
  // Disparity up to an affine map is perfectly correlated; garbage where nothing is drawn.
  targets.external_disparity = 3 / depth + 0.5;
  targets.internal_depth.narrow(1, 0, 3).fill_(100);
  targets.external_disparity.narrow(1, 0, 3).fill_(-7);
  const FusionLossTerms terms = fusion_loss(render, targets, kDepthWeights);
  EXPECT_NEAR(terms.internal_depth.item<double>(), 0, 1e-5);
  EXPECT_NEAR(terms.external_depth.item<double>(), 0, 1e-5);
}

// The rendered depth is alpha-blended z: the disparity correlated is alpha / blended z, the
// inverse of the expected depth, and pixels under alpha 0.5 are left out.
TEST_F(FusionLoss, ExternalDepthTermCorrelatesTheInverseExpectedDepthOfCoveredPixels) {
  torch::manual_seed(11);
  const torch::Tensor depth = 1 + torch::rand({kHeight, kWidth});
  torch::Tensor alpha = 0.6 + 0.4 * torch::rand({kHeight, kWidth});
  alpha.narrow(1, 0, 2).fill_(0.49);
  raster::RenderOutput render;
  render.image = random_image(7);
  render.alpha = alpha;
  render.depth = depth * alpha;
  FusionTargets targets = external_targets(5);
  targets.external_disparity = 3 / depth + 0.5;
  targets.external_disparity.narrow(1, 0, 2).fill_(-7);
  const FusionLossTerms terms =
      fusion_loss(render, targets, {TextureGuidance::External, 0.2, 0, 1e-4});
  EXPECT_NEAR(terms.external_depth.item<double>(), 0, 1e-5);
}

// The paper's weights: l = 0.2 in L_tex, li = 0.001 on L_gem^I, le = 0.0001 on L_gem^E.
TEST_F(FusionLoss, DefaultWeightsAreThePapersAndWeighTheTerms) {
  const FusionWeights defaults;
  EXPECT_EQ(defaults.texture, TextureGuidance::Masked);
  EXPECT_EQ(defaults.dssim_weight, 0.2);
  EXPECT_EQ(defaults.internal_depth, 1e-3);
  EXPECT_EQ(defaults.external_depth, 1e-4);
  EXPECT_EQ(kDiscrepancyThresholdSynthetic, 0.6);
  EXPECT_EQ(kDiscrepancyThresholdReal, 0.9);

  const torch::Tensor depth = 1 + torch::rand({kHeight, kWidth});
  raster::RenderOutput render = render_with_depth(depth, 2);
  FusionTargets targets = external_targets(6);
  targets.internal_image = random_image(9);
  targets.internal_share =
      internal_share(TextureGuidance::Masked, targets.internal_image, targets.external_image, 0.3);
  targets.internal_depth = depth + 0.5;
  torch::manual_seed(3);
  targets.external_disparity = torch::rand({kHeight, kWidth});
  const FusionLossTerms terms = fusion_loss(render, targets, defaults);
  const double texture = terms.texture.item<double>();
  EXPECT_GT(texture, 0);
  EXPECT_NEAR(terms.total.item<double>(),
              texture + 1e-3 * terms.internal_depth.item<double>() +
                  1e-4 * terms.external_depth.item<double>(),
              1e-7);  // float sums; swapping li and le would move it by about 4e-4
}

TEST_F(FusionLoss, DepthTermsPullTheRenderedDepthTowardsTheReferences) {
  const torch::Tensor depth = 1 + torch::rand({kHeight, kWidth});
  raster::RenderOutput render = render_with_depth(depth, 0);
  FusionTargets targets = external_targets(6);
  targets.internal_depth = depth + 0.5;  // everything farther
  torch::manual_seed(3);
  targets.external_disparity = torch::rand({kHeight, kWidth});
  const FusionLossTerms terms = fusion_loss(render, targets, kDepthWeights);
  EXPECT_NEAR(terms.internal_depth.item<double>(), 0.5, 1e-5);
  EXPECT_GT(terms.external_depth.item<double>(), 0.1);
  terms.total.backward();
  EXPECT_GT(render.depth.grad().abs().sum().item<double>(), 0);
  // The internal term alone pushes every rendered depth up (negative gradient).
  render.depth.mutable_grad() = torch::Tensor();
  fusion_loss(render, targets, {TextureGuidance::External, 0.2, 1e-3, 0}).total.backward();
  EXPECT_TRUE(torch::all(render.depth.grad() < 0).item<bool>());
}

TEST_F(FusionLoss, InternalDepthTermIsZeroWhereNothingIsCovered) {
  raster::RenderOutput render = render_with_depth(1 + torch::rand({kHeight, kWidth}), kWidth);
  FusionTargets targets = external_targets(8);
  targets.internal_depth = torch::full({kHeight, kWidth}, 2.0);
  const FusionLossTerms terms =
      fusion_loss(render, targets, {TextureGuidance::External, 0.2, 1e-3, 0});
  EXPECT_EQ(terms.internal_depth.item<double>(), 0);
  EXPECT_FALSE(terms.external_depth.defined());
  terms.total.backward();
  EXPECT_EQ(render.depth.grad().abs().sum().item<double>(), 0);
}

TEST_F(FusionLoss, DiscrepancyRefusesImagesItCannotCompare) {
  const torch::Tensor internal = random_image(3);
  const std::string smaller = testing::error_message(
      [&] { discrepancy(internal, internal.narrow(2, 0, kWidth - 1).contiguous()); });
  EXPECT_TRUE(testing::contains(smaller, "differs from the external image's")) << smaller;
  EXPECT_THROW(internal_share(TextureGuidance::Masked, internal, internal.to(torch::kDouble), 0.5),
               Error);
  EXPECT_THROW(internal_share(TextureGuidance::Masked, internal, torch::Tensor(), 0.5), Error);
}

TEST_F(FusionLoss, MissingReferenceOrUnknownGuidanceIsAnError) {
  EXPECT_THROW(parse_texture_guidance("mixed"), Error);
  EXPECT_EQ(parse_texture_guidance("average"), TextureGuidance::Average);
  raster::RenderOutput render;
  render.image = random_image(1).requires_grad_();
  FusionTargets targets;
  targets.external_image = random_image(2);
  targets.internal_share = torch::ones({kHeight, kWidth});  // asks for the absent internal image
  EXPECT_THROW(fusion_loss(render, targets, {TextureGuidance::Masked, 0.2, 0, 0}), Error);
  targets.external_image = torch::Tensor();
  targets.internal_share = torch::zeros({kHeight, kWidth});
  EXPECT_EQ(testing::error_message([&] {
              fusion_loss(render, targets, {TextureGuidance::External, 0.2, 0, 0});
            }),
            "fusion loss: the external texture guidance needs the external image");
}

}  // namespace
}  // namespace iesrgs::loss
