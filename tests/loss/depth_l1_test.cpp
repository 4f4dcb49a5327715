#include "loss/depth_l1.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace iesrgs::loss {
namespace {

// Six pixels: two count, one is under-covered, one has no reference, one is barely covered, and
// the last lies nearer than its reference.
struct Pixels {
  std::vector<double> depth{1.0, 3.0, 2.0, 4.0, 1.5, 1.0};
  std::vector<double> alpha{0.5, 1.0, 0.49, 1.0, 0.5, 1.0};
  std::vector<double> reference{1.5, 3.0, 1.0, 0.0, 2.0, 1.75};
};

TEST(CoveredDepthL1, MeanOverThePixelsCoveredWithAReference) {
  const Pixels p;
  const CoveredDepthL1 l1 = covered_depth_l1(p.depth.data(), p.alpha.data(), p.reference.data(), 6);
  EXPECT_EQ(l1.pixels, 4);
  // Expected depths 2, 3, 3 and 1 against 1.5, 3, 2 and 1.75.
  EXPECT_DOUBLE_EQ(l1.mean, (0.5 + 0.0 + 1.0 + 0.75) / 4);
}

TEST(CoveredDepthL1, NothingCoveredGivesZero) {
  const std::vector<double> depth(4, 1.0), alpha(4, 0.2), reference(4, 2.0);
  const CoveredDepthL1 l1 = covered_depth_l1(depth.data(), alpha.data(), reference.data(), 4);
  EXPECT_EQ(l1.pixels, 0);
  EXPECT_EQ(l1.mean, 0);
}

TEST(CoveredDepthL1, GradientOfTheQuotientOnTheCountedPixels) {
  const Pixels p;
  std::vector<double> grad_depth(6, 7.0), grad_alpha(6, 7.0);
  covered_depth_l1_backward(p.depth.data(), p.alpha.data(), p.reference.data(), 6, 0.25,
                            grad_depth.data(), grad_alpha.data());
  // Pixel 0: expected 2 > 1.5, d/d depth = 1 / alpha, d/d alpha = -depth / alpha^2.
  EXPECT_DOUBLE_EQ(grad_depth[0], 0.25 / 0.5);
  EXPECT_DOUBLE_EQ(grad_alpha[0], -0.25 * 1.0 / 0.25);
  // Pixel 1 sits on its reference: |t| has derivative 0 at 0. Pixels 2 and 3 do not count.
  for (int i : {1, 2, 3}) {
    EXPECT_EQ(grad_depth[i], 0) << i;
    EXPECT_EQ(grad_alpha[i], 0) << i;
  }
  // Pixel 4: expected 3 > 2.
  EXPECT_DOUBLE_EQ(grad_depth[4], 0.25 / 0.5);
  EXPECT_DOUBLE_EQ(grad_alpha[4], -0.25 * 1.5 / 0.25);
  // Pixel 5: expected 1 < 1.75, so the signs turn.
  EXPECT_DOUBLE_EQ(grad_depth[5], -0.25 / 1.0);
  EXPECT_DOUBLE_EQ(grad_alpha[5], 0.25 * 1.0 / 1.0);
}

}  // namespace
}  // namespace iesrgs::loss
