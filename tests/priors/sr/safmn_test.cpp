#include "priors/sr/safmn.hpp"

#include <gtest/gtest.h>

#include "priors/sr/sr_test_support.hpp"

namespace iesrgs::priors::sr {
namespace {

using sr_testing::kReleasedWeights;
using sr_testing::lego_crop;

TEST(Safmn, InputsBelowThePoolingPyramidArePaddedAndCropped) {
  const auto file = kReleasedWeights / "SAFMN_x4.pth";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not found (shared data absent)";
  const auto net = make_sr_net("safmn", file, 4);
  const torch::Tensor crop = lego_crop();
  const torch::Tensor corner = net->upscale(crop.narrow(2, 0, 7).narrow(3, 0, 9).contiguous());
  ASSERT_EQ(corner.sizes(), torch::IntArrayRef({1, 3, 28, 36}));
  // The same corner with real context around it instead of replicated edges: padding on the
  // wrong side or cropping the wrong part would misalign the two.
  const torch::Tensor in_context = net->upscale(crop).narrow(2, 0, 28).narrow(3, 0, 36);
  EXPECT_LT((corner - in_context).abs().mean().item<float>(), 0.02);
}

}  // namespace
}  // namespace iesrgs::priors::sr
