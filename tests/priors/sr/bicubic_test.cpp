#include "priors/sr/bicubic.hpp"

#include <gtest/gtest.h>

#include "priors/sr/sr_test_support.hpp"
#include "support/expect_error.hpp"

namespace iesrgs::priors::sr {
namespace {

TEST(Bicubic, UpscalesLikePillow) {
  // Pillow's float ("F" mode) resize: the same filter as its 8-bit path, without the
  // quantization and clipping between passes.
  const torch::Tensor pillow =
      sr_testing::read_npy_tensor(sr_testing::kFixtures / "bicubic_x4_lego.npy");
  EXPECT_LT(
      sr_testing::max_abs_difference(make_bicubic(4)->upscale(sr_testing::lego_crop()), pillow),
      1e-5);
}

TEST(Bicubic, KeepsFlatColours) {
  const torch::Tensor flat = torch::full({1, 3, 5, 7}, 0.3f);
  const torch::Tensor out = make_bicubic(3)->upscale(flat);
  ASSERT_EQ(out.sizes(), torch::IntArrayRef({1, 3, 15, 21}));
  EXPECT_LT((out - 0.3f).abs().max().item<float>(), 1e-6);
}

TEST(Bicubic, RejectsBadScalesAndInputs) {
  EXPECT_NE(iesrgs::testing::error_message([] { make_bicubic(0); }).find("invalid scale 0"),
            std::string::npos);
  const std::string message = iesrgs::testing::error_message([] {
    make_bicubic(2)->upscale(torch::zeros({1, 4, 5, 5}));
  });
  EXPECT_NE(message.find("bicubic: expected an RGB batch"), std::string::npos) << message;
}

}  // namespace
}  // namespace iesrgs::priors::sr
