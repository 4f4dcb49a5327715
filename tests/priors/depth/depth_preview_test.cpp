#include "priors/depth/depth_preview.hpp"

#include <gtest/gtest.h>

#include "support/expect_error.hpp"

namespace iesrgs::priors::depth {
namespace {

int brightness(const Image8& image, int x) {
  return image.at(x, 0, 0) + image.at(x, 0, 1) + image.at(x, 0, 2);
}

TEST(DepthPreview, RampRunsFromDarkAtTheMinimumToBrightAtTheMaximum) {
  const Image8 preview = depth_preview(torch::linspace(-3, 5, 64).view({1, 64}));
  ASSERT_EQ(preview.width, 64);
  ASSERT_EQ(preview.height, 1);
  ASSERT_EQ(preview.channels, 3);
  EXPECT_EQ(brightness(preview, 0), 4);
  EXPECT_GT(brightness(preview, 63), 600);
  for (int x = 1; x < 64; ++x) EXPECT_GT(brightness(preview, x), brightness(preview, x - 1)) << x;
}

TEST(DepthPreview, ScaleAndOffsetDoNotMatter) {
  const torch::Tensor depth = torch::rand({5, 7});
  EXPECT_EQ(depth_preview(depth).data, depth_preview(depth * 40 + 3).data);
}

TEST(DepthPreview, ConstantMapIsDark) {
  const Image8 preview = depth_preview(torch::full({3, 2}, 7.f));
  for (int x = 0; x < 2; ++x) EXPECT_EQ(brightness(preview, x), 4);
}

TEST(DepthPreview, RejectsAnythingButAMap) {
  const std::string message = testing::error_message([] {
    depth_preview(torch::zeros({2, 3, 4}));
  });
  EXPECT_NE(message.find("2x3x4"), std::string::npos) << message;
}

}  // namespace
}  // namespace iesrgs::priors::depth
