#include "priors/sr/swinir.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "priors/sr/sr_test_support.hpp"
#include "support/expect_error.hpp"
#include "support/module_shapes.hpp"

// Fixtures come from tests/data/priors/swinir/make_fixtures.py, which runs the authors'
// network_swinir.py: small official-layout networks with seeded weights, their input and
// output under the official test procedure, and the state-dict layout of SwinIR-M x4 and
// SwinIR-S x2.
namespace iesrgs::priors::sr {
namespace {

using iesrgs::testing::error_message;
using iesrgs::testing::parameter_shapes;
using iesrgs::testing::read_parameter_shapes;
using iesrgs::testing::zero_state_dict;
using sr_testing::read_npy_tensor;

const std::filesystem::path kData = std::filesystem::path(IESRGS_TEST_DATA) / "priors/swinir";

void expect_same_config(const SwinIRConfig& a, const SwinIRConfig& b) {
  EXPECT_EQ(a.embed_dim, b.embed_dim);
  EXPECT_EQ(a.depths, b.depths);
  EXPECT_EQ(a.num_heads, b.num_heads);
  EXPECT_EQ(a.window_size, b.window_size);
  EXPECT_EQ(a.mlp_hidden_dim, b.mlp_hidden_dim);
  EXPECT_EQ(a.upsampler, b.upsampler);
  EXPECT_EQ(a.scale, b.scale);
  EXPECT_EQ(a.three_conv, b.three_conv);
  if (a.upsampler != SwinIRUpsampler::PixelShuffleDirect) {
    EXPECT_EQ(a.num_feat, b.num_feat);
  }
}

TEST(SwinIR, RealConfigurationsHaveTheOfficialStateDictLayout) {
  SwinIR m(swinir_m_config(4));
  SwinIR s(swinir_s_config(2));
  EXPECT_EQ(parameter_shapes(*m), read_parameter_shapes(kData / "swinir_m_x4_names.txt"));
  EXPECT_EQ(parameter_shapes(*s), read_parameter_shapes(kData / "swinir_s_x2_names.txt"));
  // The parameter counts the official code gives (11.9M as the paper reports for SwinIR-M).
  const auto count = [](SwinIR& net) {
    int64_t total = 0;
    for (const auto& p : net->parameters()) total += p.numel();
    return total;
  };
  EXPECT_EQ(count(m), 11900199);
  EXPECT_EQ(count(s), 910152);
}

TEST(SwinIR, InfersEveryOfficialClassicalConfigurationFromShapes) {
  std::vector<SwinIRConfig> configs;
  for (int scale : {2, 3, 4, 8}) configs.push_back(swinir_m_config(scale));
  for (int scale : {2, 3, 4}) configs.push_back(swinir_s_config(scale));
  for (const SwinIRConfig& config : configs) {
    SwinIR net(config);
    SCOPED_TRACE("embed_dim " + std::to_string(config.embed_dim) + " x" +
                 std::to_string(config.scale));
    expect_same_config(infer_swinir_config(zero_state_dict(parameter_shapes(*net)), "net.pth"),
                       config);
  }
}

void expect_matches_official(const std::string& name, int scale) {
  const std::unique_ptr<SrNet> net = make_swinir(kData / (name + ".pth"), scale);
  EXPECT_EQ(net->scale(), scale);
  const torch::Tensor input = read_npy_tensor(kData / (name + "_in.npy"));
  const torch::Tensor expected = read_npy_tensor(kData / (name + "_out.npy"));
  const torch::Tensor output = net->upscale(input);
  ASSERT_EQ(output.sizes(), expected.sizes());
  EXPECT_LT((output - expected).abs().max().item<float>(), 1e-4f);
}

// 13x21 input: both sides need padding.
TEST(SwinIR, PixelShuffleMatchesOfficialCode) {
  expect_matches_official("tiny_pixelshuffle_x2", 2);
}

// 16x11 input: the height, already a window multiple, still gets a whole window of mirror.
TEST(SwinIR, PixelShuffleDirectMatchesOfficialCode) {
  expect_matches_official("tiny_pixelshuffledirect_x3", 3);
}

// The real-world models' upsampler, at x2 (one nearest step) and at x4 (two) with the large
// model's '3conv' bottlenecks.
TEST(SwinIR, NearestConvMatchesOfficialCode) {
  expect_matches_official("tiny_nearestconv_x2", 2);
  expect_matches_official("tiny_nearestconv_3conv_x4", 4);
}

// SwinIR-M and SwinIR-L for real-world SR (003_realSR_BSRGAN_DFO*_s64w8_SwinIR-{M,L}_x4_GAN).
TEST(SwinIR, InfersTheRealWorldModelsFromTheirLayout) {
  for (const auto& [names, large] : std::vector<std::pair<std::string, bool>>{
           {"swinir_real_m_x4", false}, {"swinir_real_l_x4", true}}) {
    SCOPED_TRACE(names);
    const auto official = read_parameter_shapes(kData / (names + "_names.txt"));
    const SwinIRConfig config = infer_swinir_config(zero_state_dict(official), "real.pth");
    EXPECT_EQ(config.upsampler, SwinIRUpsampler::NearestConv);
    EXPECT_EQ(config.scale, 4);
    EXPECT_EQ(config.three_conv, large);
    EXPECT_EQ(config.embed_dim, large ? 240 : 180);
    EXPECT_EQ(config.depths.size(), large ? 9u : 6u);
    EXPECT_EQ(config.num_heads[0], large ? 8 : 6);
    SwinIR net(config);
    EXPECT_EQ(parameter_shapes(*net), official);
  }
}

TEST(SwinIR, LoadsWithAnExplicitConfiguration) {
  const std::filesystem::path file = kData / "tiny_pixelshuffledirect_x3.pth";
  SwinIRConfig config = swinir_s_config(3);
  config.embed_dim = 16;
  config.depths = {2, 3};
  config.num_heads = {2, 4};
  config.mlp_hidden_dim = 32;
  EXPECT_EQ(make_swinir(file, config)->upscale(torch::rand({1, 3, 5, 7})).sizes(),
            (std::vector<int64_t>{1, 3, 15, 21}));
  const std::string message = error_message([&] { make_swinir(file, swinir_s_config(3)); });
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
}

TEST(SwinIR, RejectsAScaleOtherThanTheCheckpoints) {
  const std::filesystem::path file = kData / "tiny_pixelshuffle_x2.pth";
  const std::string message = error_message([&] { make_swinir(file, 4); });
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_NE(message.find("x2 SwinIR checkpoint, but x4"), std::string::npos) << message;
}

void expect_layout_rejected(const StateDict& weights, const std::string& problem) {
  SCOPED_TRACE(problem);
  const std::string message = error_message([&] { infer_swinir_config(weights, "odd.pth"); });
  EXPECT_EQ(message.rfind("odd.pth: ", 0), 0u) << message;
  EXPECT_NE(message.find(problem), std::string::npos) << message;
}

TEST(SwinIR, RejectsLayoutsItDoesNotRun) {
  SwinIR net(swinir_s_config(2));
  const StateDict official = zero_state_dict(parameter_shapes(*net));
  expect_layout_rejected({}, "no conv_first.weight");

  StateDict headless = official;
  headless["conv_up1.weight"] = torch::zeros({64, 64, 3, 3});
  expect_layout_rejected(headless, "'nearest+conv' upsampler without conv_before_upsample.0");

  StateDict denoiser = official;
  denoiser.erase("upsample.0.weight");
  expect_layout_rejected(denoiser, "without an upsampler");

  StateDict flat_upsample = official;
  flat_upsample["upsample.0.weight"] = torch::zeros({});
  expect_layout_rejected(flat_upsample, "upsample.0.weight has 0 dimensions, not 4");

  StateDict odd_heads = official;
  odd_heads["layers.1.residual_group.blocks.0.attn.relative_position_bias_table"] =
      torch::zeros({225, 7});
  expect_layout_rejected(odd_heads, "7 heads do not divide the embedding width 60");

  StateDict huge_window = official;
  huge_window["layers.0.residual_group.blocks.0.attn.relative_position_bias_table"] =
      torch::zeros({}).expand({199 * 199, 6});
  expect_layout_rejected(huge_window, "window size 100 is outside");
}

TEST(SwinIR, UpscalesAnySizeByMirroringPastTheWindow) {
  torch::manual_seed(0);
  SwinIRConfig config = swinir_s_config(2);
  config.embed_dim = 12;
  config.depths = {2};
  config.num_heads = {2};
  const std::unique_ptr<SrNet> upscaler = swinir_sr(SwinIR(config));
  for (const auto& [height, width] : std::vector<std::pair<int, int>>{{1, 1}, {3, 17}, {8, 8}}) {
    const torch::Tensor out = upscaler->upscale(torch::rand({1, 3, height, width}));
    EXPECT_EQ(out.sizes(), (std::vector<int64_t>{1, 3, 2 * height, 2 * width}));
    EXPECT_TRUE(out.isfinite().all().item<bool>());
  }
  const std::string message = error_message([&] { upscaler->upscale(torch::rand({1, 1, 8, 8})); });
  EXPECT_NE(message.find("swinir: expected an RGB batch of shape (1, 3, H, W)"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace iesrgs::priors::sr
