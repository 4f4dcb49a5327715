#include "eval/mask_agreement.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <vector>

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
  EXPECT_DOUBLE_EQ(counts.oracle_mask_share(), 2.0 / 16);
  EXPECT_EQ(counts.oracle_error, 0);
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
  EXPECT_EQ(counts.closer, 0);
  EXPECT_EQ(counts.oracle_error, 0);
}

// Each reference is right at some pixels and wrong at others; where both are equally close the
// external image stays.
TEST(MaskAgreement, OracleMaskTakesTheCloserReferencePerPixel) {
  const torch::Tensor truth = image_with({}, 0);
  torch::Tensor internal = image_with({1, 2}, 0.9f);            // wrong at 1 and 2
  torch::Tensor external = image_with({7, 8}, 0.2f);            // wrong at 7 and 8
  internal.index_put_({torch::indexing::Slice(), 2, 0}, 0.3f);  // pixel 8: off by 0.2, not 0.3
  external.index_put_({torch::indexing::Slice(), 0, 2}, 0.9f);  // pixel 2: a tie
  const torch::Tensor mask = oracle_mask(internal, external, truth);
  EXPECT_EQ(mask.sizes(), torch::IntArrayRef({4, 4}));
  const torch::Tensor picked = mask.nonzero().flatten().contiguous();  // (row, column) pairs
  EXPECT_EQ(
      std::vector<int64_t>(picked.data_ptr<int64_t>(), picked.data_ptr<int64_t>() + picked.numel()),
      std::vector<int64_t>({1, 3, 2, 0}));
  const MaskCounts counts = mask_counts(internal, external, truth, 0.6);
  EXPECT_EQ(counts.closer, 2);
  // Pixel 2 keeps the external image's 0.4 error, pixel 8 takes the internal image's 0.2.
  EXPECT_NEAR(counts.oracle_error, 3 * (0.4 * 0.4 + 0.2 * 0.2), 1e-5);
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
