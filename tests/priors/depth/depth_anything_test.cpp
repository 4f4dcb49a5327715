// Depth Anything V2 against the authors' code: fixtures from tests/data/priors/depth/
// make_fixtures.py, a small official-layout model with seeded weights.
#include "priors/depth/depth_anything.hpp"

#include <gtest/gtest.h>

#include <map>

#include "io/image.hpp"
#include "io/image_tensor.hpp"
#include "support/expect_error.hpp"
#include "support/module_shapes.hpp"
#include "support/tensor_files.hpp"

namespace iesrgs::priors::depth {
namespace {

using testing::error_message;
using testing::max_abs_difference;
using testing::parameter_shapes;
using testing::ParameterShapes;
using testing::read_parameter_shapes;

const std::filesystem::path kData = std::filesystem::path(IESRGS_TEST_DATA) / "priors" / "depth";

torch::Tensor read_tensor(const std::string& name) {
  return testing::read_npy_tensor(kData / name);
}

torch::Tensor fixture_image() {
  const float black[3] = {0, 0, 0};
  return to_tensor(composite_rgb(read_image8(kData / "image.png"), black));
}

// The sizes make_fixtures.py gives the official classes.
DepthAnythingConfig tiny_config() {
  DepthAnythingConfig config;
  config.vit = {24, 5, 2, 4, 14, 4};
  config.head = {8, {6, 12, 16, 24}};
  config.taken_blocks = {1, 2, 3, 4};
  return config;
}

DepthAnythingV2 tiny_model() {
  const std::filesystem::path file = kData / "tiny.pth";
  return load_depth_anything(tiny_config(), read_state_dict(file), file);
}

class DepthAnythingForward : public ::testing::TestWithParam<std::string> {};

// 56x56 takes the shortcut that keeps the trained positional table, 42x70 interpolates it.
TEST_P(DepthAnythingForward, MatchesTheAuthorsCode) {
  const torch::Tensor input = read_tensor("net_" + GetParam() + "_in.npy");
  const torch::Tensor expected = read_tensor("net_" + GetParam() + "_out.npy");
  torch::NoGradGuard no_grad;
  const torch::Tensor output = tiny_model()->forward(input);
  EXPECT_LT(max_abs_difference(output, expected), 1e-4f);
  EXPECT_GT(expected.std().item<float>(), 0.1f);  // the fixture is not flat
}

INSTANTIATE_TEST_SUITE_P(Fixtures, DepthAnythingForward, ::testing::Values("56x56", "42x70"));

TEST(DepthAnything, InputSizeFollowsTheAuthorsLowerBoundResize) {
  using Size = std::pair<int64_t, int64_t>;
  // Values from the authors' Resize.get_size; 2x5 lands on 92.5 patches, which numpy rounds
  // to the even 92.
  const std::map<Size, Size> expected{
      {{200, 200}, {518, 518}}, {{27, 40}, {518, 770}},     {{200, 300}, {518, 784}},
      {{600, 800}, {518, 686}}, {{1080, 1920}, {518, 924}}, {{300, 217}, {714, 518}},
      {{518, 700}, {518, 700}}, {{1, 1}, {518, 518}},       {{2, 5}, {518, 1288}}};
  for (const auto& [in, out] : expected)
    EXPECT_EQ(network_input_size(in.first, in.second, 518), out) << in.first << "x" << in.second;
}

// Enlarged to a 70 short side, reduced to a 28 one.
TEST(DepthAnything, PreprocessingMatchesTheAuthorsCv2Resize) {
  for (const int side : {70, 28}) {
    const torch::Tensor expected = read_tensor("image_" + std::to_string(side) + "_in.npy");
    EXPECT_LT(max_abs_difference(network_input(fixture_image(), side), expected), 1e-5f) << side;
  }
}

TEST(DepthAnything, PredictMatchesTheAuthorsInferImage) {
  DepthAnythingNet net(tiny_model(), "tiny");
  const torch::Tensor rgb = fixture_image();
  const torch::Tensor depth = net.predict(rgb);
  EXPECT_EQ(depth.sizes(), (std::vector<int64_t>{rgb.size(2), rgb.size(3)}));
  EXPECT_FALSE(depth.requires_grad());
  EXPECT_LT(max_abs_difference(depth, read_tensor("image_depth.npy")), 1e-4f);
}

TEST(DepthAnything, PredictRejectsAnythingButOneRgbImage) {
  DepthAnythingNet net(tiny_model(), "tiny");
  const std::string message = error_message([&] { net.predict(torch::zeros({1, 4, 20, 20})); });
  EXPECT_NE(message.find("tiny"), std::string::npos) << message;
  EXPECT_NE(message.find("1x4x20x20"), std::string::npos) << message;
}

TEST(DepthAnything, SlicedAttentionEqualsWholeAttention) {
  torch::manual_seed(3);
  Attention whole(24, 2), sliced(24, 2, /*max_scores=*/2 * 50 * 7);  // 7 query rows per slice
  torch::NoGradGuard no_grad;
  for (const auto& entry : whole->named_parameters())
    sliced->named_parameters()[entry.key()].copy_(entry.value());
  const torch::Tensor x = torch::randn({1, 50, 24});
  EXPECT_LT(max_abs_difference(sliced(x), whole(x)), 1e-6f);
}

TEST(DepthAnything, VitsHasTheOfficialNamesAndShapes) {
  const ParameterShapes expected = read_parameter_shapes(kData / "vits_names.txt");
  ASSERT_EQ(expected.size(), 239u);
  const DepthAnythingV2 model(depth_anything_config("vits"));
  EXPECT_EQ(parameter_shapes(*model), expected);
}

TEST(DepthAnything, EncoderIsJudgedByTheEmbeddingWidth) {
  EXPECT_EQ(depth_anything_encoder({{"pretrained.cls_token", torch::zeros({1, 1, 768})}}, "b.pth"),
            "vitb");
  const std::string tiny = error_message(
      [] { depth_anything_encoder(read_state_dict(kData / "tiny.pth"), "tiny.pth"); });
  EXPECT_NE(tiny.find("tiny.pth: embedding width 24 matches no released"), std::string::npos)
      << tiny;
  const std::string other = error_message([] { depth_anything_encoder({}, "other.pth"); });
  EXPECT_NE(other.find("other.pth: not a Depth Anything V2 checkpoint"), std::string::npos)
      << other;
}

}  // namespace
}  // namespace iesrgs::priors::depth
