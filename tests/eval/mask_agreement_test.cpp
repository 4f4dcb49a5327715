#include "eval/mask_agreement.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

namespace iesrgs::eval {
namespace {

// A gray (3, 4, 4) image with the pixels of `dark` (row-major indices) set to `value`.
torch::Tensor image_with(std::initializer_list<int> dark, float value) {
  torch::Tensor image = torch::full({3, 4, 4}, 0.5f);
  for (int p : dark) image.index_put_({torch::indexing::Slice(), p / 4, p % 4}, value);
  return image;
}

TEST(MaskAgreement, MaskFindsTheWrongExternalPixelsWhenTheInternalImageIsRight) {
  const torch::Tensor truth = image_with({}, 0);
  const torch::Tensor external = image_with({3, 9}, 0.05f);  // D = 0.45 / 0.5 = 0.9 there
  const MaskCounts counts = mask_counts(truth, external, truth, 0.6);
  EXPECT_EQ(counts.pixels, 16);
  EXPECT_EQ(counts.mask, 2);
  EXPECT_EQ(counts.truth_mask, 2);
  EXPECT_DOUBLE_EQ(counts.iou(), 1);
  EXPECT_DOUBLE_EQ(counts.precision(), 1);
  EXPECT_DOUBLE_EQ(counts.internal_closer_share(), 1);
  EXPECT_DOUBLE_EQ(counts.mask_share(), 2.0 / 16);
  EXPECT_EQ(counts.fused_error, 0);  // the mask swaps exactly the wrong pixels for right ones
  EXPECT_NEAR(counts.external_error, 2 * 3 * 0.45 * 0.45, 1e-5);
}

TEST(MaskAgreement, MaskPicksTheWrongInternalPixels) {
  const torch::Tensor truth = image_with({}, 0);
  const torch::Tensor internal = image_with({5}, 0.1f);  // D = 0.4 / 0.1 = 4: picked, and wrong
  const MaskCounts counts = mask_counts(internal, truth, truth, 0.6);
  EXPECT_EQ(counts.mask, 1);
  EXPECT_EQ(counts.truth_mask, 0);
  EXPECT_DOUBLE_EQ(counts.precision(), 0);
  EXPECT_DOUBLE_EQ(counts.recall(), 0);  // an empty G: no pixel to find
  EXPECT_DOUBLE_EQ(counts.internal_closer_share(), 0);
  // The fused reference takes the one wrong pixel: 3 of 48 values off by 0.4, MSE 0.01.
  EXPECT_NEAR(counts.fused_psnr(), 20, 1e-4);
  EXPECT_EQ(counts.external_error, 0);
}

TEST(MaskAgreement, PsnrAveragesOverTheImagesOwnChannels) {
  const torch::Tensor truth = torch::full({1, 4, 4}, 0.5f);
  torch::Tensor internal = truth.clone();
  internal.index_put_({0, 1, 1}, 0.1f);  // 1 of 16 values off by 0.4: MSE 0.01
  const MaskCounts counts = mask_counts(internal, truth, truth, 0.6);
  EXPECT_EQ(counts.values, 16);
  EXPECT_NEAR(counts.internal_psnr(), 20, 1e-4);
}

TEST(MaskAgreement, CountsAddUp) {
  const torch::Tensor truth = image_with({}, 0);
  MaskCounts sum = mask_counts(truth, image_with({3, 9}, 0.05f), truth, 0.6);
  sum += mask_counts(image_with({5}, 0.1f), truth, truth, 0.6);
  EXPECT_EQ(sum.pixels, 32);
  EXPECT_EQ(sum.values, 96);
  EXPECT_EQ(sum.mask, 3);
  EXPECT_EQ(sum.both, 2);
  EXPECT_DOUBLE_EQ(sum.precision(), 2.0 / 3);
  EXPECT_DOUBLE_EQ(sum.iou(), 2.0 / 3);
  EXPECT_NEAR(sum.fused_error, 3 * 0.4 * 0.4, 1e-5);
}

}  // namespace
}  // namespace iesrgs::eval
