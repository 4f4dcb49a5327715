#include "loss/texture_fusion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "loss/loss_test_support.hpp"
#include "loss/photometric.hpp"

namespace iesrgs::loss {
namespace {

using loss_testing::numeric_gradient;
using loss_testing::random_values;

TEST(DiscrepancyMask, ThresholdsTheChannelMeanOfTheRelativeDifference) {
  const ImageShape shape{3, 1, 3};
  // Pixel 0 has D = 0.8, pixel 1 D = 0.2. Pixel 2 differs in its dark red only: the channel
  // ratios (1, 0, 0) average to 1/3, while the ratio of the channel means would be 0.05.
  const std::vector<float> internal{0.5f, 0.5f, 0.1f,   // red plane
                                    0.5f, 0.5f, 1.0f,   // green
                                    0.5f, 0.5f, 1.0f};  // blue
  const std::vector<float> external{0.9f, 0.6f, 0.2f, 0.9f, 0.6f, 1.0f, 0.9f, 0.6f, 1.0f};
  EXPECT_EQ(discrepancy_mask(internal.data(), external.data(), shape, 0.3),
            (std::vector<uint8_t>{1, 0, 1}));
  EXPECT_EQ(discrepancy_mask(internal.data(), external.data(), shape, kDiscrepancyThresholdReal),
            (std::vector<uint8_t>{0, 0, 0}));
}

// M(p) = [D(p) >= T]: a pixel whose discrepancy is the threshold itself takes the internal image.
TEST(DiscrepancyMask, APixelAtTheThresholdIsMasked) {
  const ImageShape shape{3, 1, 1};
  const std::vector<double> internal{0.5, 0.7, 0.3}, external{0.9, 0.6, 0.2};
  const double d = discrepancy_map(internal.data(), external.data(), shape)[0];
  EXPECT_EQ(discrepancy_mask(internal.data(), external.data(), shape, d)[0], 1);
  EXPECT_EQ(discrepancy_mask(internal.data(), external.data(), shape, std::nextafter(d, 1.0))[0],
            0);
}

TEST(DiscrepancyMask, BlackInternalPixelsAlwaysDisagree) {
  const ImageShape shape{1, 1, 1};
  const std::vector<float> internal{0.f}, external{0.01f};
  EXPECT_EQ(discrepancy_mask(internal.data(), external.data(), shape, 0.9)[0], 1);
}

struct Views {
  ImageShape shape{15, 12, 3};
  std::vector<double> render = random_values(shape.values(), 1, 0.0, 0.45);
  std::vector<double> internal = random_values(shape.values(), 2, 0.5, 1.0);
  std::vector<double> external = random_values(shape.values(), 3, 0.5, 1.0);
};

double guided_loss(const Views& v, const std::vector<double>& share, std::vector<double>* grad) {
  return guided_texture_loss(v.render.data(), v.internal.data(), v.external.data(), share.data(),
                             v.shape, kDssimWeight, grad ? grad->data() : nullptr);
}

// Loss and gradient of the photometric loss against one reference.
double photometric(const Views& v, const std::vector<double>& reference,
                   std::vector<double>* grad) {
  return photometric_loss(v.render.data(), reference.data(), v.shape, kDssimWeight, grad->data());
}

TEST(GuidedTexture, ShareZeroUsesTheExternalImageShareOneTheInternal) {
  const Views v;
  for (double value : {0.0, 1.0}) {
    const std::vector<double> share(v.shape.pixels(), value);
    std::vector<double> grad(v.shape.values(), 0.0), expected_grad = grad;
    const double loss = guided_loss(v, share, &grad);
    const double expected = photometric(v, value ? v.internal : v.external, &expected_grad);
    EXPECT_NEAR(loss, expected, 1e-12);
    for (size_t i = 0; i < grad.size(); ++i) EXPECT_NEAR(grad[i], expected_grad[i], 1e-12);
  }
}

TEST(GuidedTexture, HalfShareAveragesBothReferences) {
  const Views v;
  const std::vector<double> half(v.shape.pixels(), 0.5);
  std::vector<double> unused(v.shape.values(), 0.0);
  EXPECT_NEAR(guided_loss(v, half, nullptr),
              0.5 * (photometric(v, v.internal, &unused) + photometric(v, v.external, &unused)),
              1e-12);
}

TEST(GuidedTexture, ExternalAloneNeedsNoInternalImage) {
  const Views v;
  const std::vector<double> zero(v.shape.pixels(), 0.0);
  std::vector<double> unused(v.shape.values(), 0.0);
  EXPECT_NEAR(
      guided_texture_loss(v.render.data(), static_cast<const double*>(nullptr), v.external.data(),
                          zero.data(), v.shape, kDssimWeight, static_cast<double*>(nullptr)),
      photometric(v, v.external, &unused), 1e-12);
}

TEST(GuidedTexture, RenderEqualToBothReferencesGivesZero) {
  const Views v;
  const std::vector<uint8_t> mask = discrepancy_mask(v.internal.data(), v.external.data(), v.shape,
                                                     kDiscrepancyThresholdSynthetic);
  const std::vector<double> share(mask.begin(), mask.end());
  EXPECT_NEAR(guided_texture_loss(v.render.data(), v.render.data(), v.render.data(), share.data(),
                                  v.shape, kDssimWeight, static_cast<double*>(nullptr)),
              0.0, 1e-12);
}

TEST(GuidedTexture, GradientMatchesFiniteDifferences) {
  Views v;
  std::vector<double> share(v.shape.pixels());
  for (size_t p = 0; p < share.size(); ++p) share[p] = (p * 7) % 3 == 0;
  std::vector<double> grad(v.shape.values(), 0.0);
  guided_loss(v, share, &grad);
  const auto loss = [&](const std::vector<double>& render) {
    Views at = v;
    at.render = render;
    return guided_loss(at, share, nullptr);
  };
  loss_testing::expect_gradient_near(grad, numeric_gradient(v.render, loss), 1e-4);
}

}  // namespace
}  // namespace iesrgs::loss
