#include "eval/lpips.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "eval/metrics.hpp"
#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "priors/state_dict.hpp"
#include "support/expect_error.hpp"
#include "support/scoped_env.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::eval {
namespace {

namespace fs = std::filesystem;
using testing::error_message;
using testing::ScopedEnv;

// Written by tests/data/eval/lpips/make_lpips_fixtures.py from the official LPIPS code: three
// image pairs and the official distances for each, with the real linear heads and the stand-in
// backbone below.
const fs::path kFixtures = fs::path(IESRGS_TEST_DATA) / "eval" / "lpips";
const fs::path kHeads = fs::path(IESRGS_SHARED_DATA) / "weights" / "lpips" / "v0.1";

uint32_t lowbias32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  return x ^ (x >> 16);
}

// The fixture script's formula (see its docstring), bit for bit: uniform in [-bound, bound).
torch::Tensor hashed_weights(std::vector<int64_t> shape, uint32_t seed, float bound) {
  torch::Tensor values = torch::empty(shape);
  float* out = values.data_ptr<float>();
  for (int64_t i = 0; i < values.numel(); ++i) {
    const uint32_t hash = lowbias32(uint32_t(i) ^ (seed * 0x9E3779B9u));
    out[i] = (2.f * float(hash >> 8) * 0x1p-24f - 1.f) * bound;
  }
  return values;
}

struct ConvShape {
  int index;  // in torchvision's features stack
  int64_t out, in, kernel;
};

// torchvision's layouts, written out independently of the implementation under test.
const std::vector<ConvShape> kAlexnetConvs = {
    {0, 64, 3, 11}, {3, 192, 64, 5}, {6, 384, 192, 3}, {8, 256, 384, 3}, {10, 256, 256, 3}};
const std::vector<ConvShape> kVgg16Convs = {
    {0, 64, 3, 3},     {2, 64, 64, 3},    {5, 128, 64, 3},   {7, 128, 128, 3},  {10, 256, 128, 3},
    {12, 256, 256, 3}, {14, 256, 256, 3}, {17, 512, 256, 3}, {19, 512, 512, 3}, {21, 512, 512, 3},
    {24, 512, 512, 3}, {26, 512, 512, 3}, {28, 512, 512, 3}};

// A torchvision-style checkpoint of stand-in weights, classifier entry included.
const priors::StateDict& stand_in_backbone(LpipsNet net) {
  static std::map<LpipsNet, priors::StateDict> cache;
  priors::StateDict& weights = cache[net];
  if (!weights.empty()) return weights;
  for (const ConvShape& conv : net == LpipsNet::Alex ? kAlexnetConvs : kVgg16Convs) {
    const std::string prefix = "features." + std::to_string(conv.index);
    const auto fan_in = float(conv.in * conv.kernel * conv.kernel);
    weights[prefix + ".weight"] = hashed_weights({conv.out, conv.in, conv.kernel, conv.kernel},
                                                 2 * conv.index, std::sqrt(6.f / fan_in));
    weights[prefix + ".bias"] = hashed_weights({conv.out}, 2 * conv.index + 1, 0.1f);
  }
  weights["classifier.6.bias"] = torch::zeros({1000});
  return weights;
}

fs::path heads_file(LpipsNet net) {
  return kHeads / (net == LpipsNet::Alex ? "alex.pth" : "vgg.pth");
}

Lpips stand_in_lpips(LpipsNet net) {
  return Lpips::from_state_dicts(net, stand_in_backbone(net),
                                 priors::read_state_dict(heads_file(net)),
                                 {"stand-in.pth", heads_file(net)});
}

// (3, H, W) in [0, 1].
torch::Tensor read_rgb(const fs::path& path) {
  Image image = to_float(read_image8(path));
  return torch::tensor(image.data).view({image.height, image.width, 3}).permute({2, 0, 1});
}

std::vector<std::pair<torch::Tensor, torch::Tensor>> fixture_pairs() {
  std::vector<std::pair<torch::Tensor, torch::Tensor>> pairs;
  for (int k = 0; k < 3; ++k) {
    const std::string stem = "pair" + std::to_string(k);
    pairs.emplace_back(read_rgb(kFixtures / (stem + "_a.png")),
                       read_rgb(kFixtures / (stem + "_b.png")));
  }
  return pairs;
}

class LpipsFixture : public ::testing::TestWithParam<LpipsNet> {
 protected:
  void SetUp() override {
    if (!fs::exists(kHeads)) GTEST_SKIP() << "LPIPS heads not found: " << kHeads;
  }
  Lpips load() const { return stand_in_lpips(GetParam()); }
};

TEST_P(LpipsFixture, MatchesOfficialImplementation) {
  const auto expected = nlohmann::json::parse(read_file(kFixtures / "expected.json"));
  const std::vector<float> official = expected.at(lpips_net_name(GetParam()));
  const auto pairs = fixture_pairs();
  ASSERT_EQ(official.size(), pairs.size());
  Lpips lpips = load();
  for (size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_NEAR(lpips.distance(pairs[k].first, pairs[k].second), official[k], 1e-6) << "pair " << k;
  }
}

TEST_P(LpipsFixture, IdenticalImagesAreZeroApart) {
  const auto pairs = fixture_pairs();
  EXPECT_EQ(load().distance(pairs[0].first, pairs[0].first), 0.f);
}

TEST_P(LpipsFixture, IsSymmetricAndTakesBatchedImages) {
  const auto [a, b] = fixture_pairs()[2];
  Lpips lpips = load();
  const float ab = lpips.distance(a, b);
  EXPECT_NEAR(lpips.distance(b, a), ab, 1e-6);
  EXPECT_EQ(lpips.distance(a.unsqueeze(0), b.unsqueeze(0)), ab);
}

TEST_P(LpipsFixture, RejectsMismatchedOrTooSmallImages) {
  Lpips lpips = load();
  const auto image = torch::rand({3, 40, 40});
  EXPECT_NE(error_message([&] {
              lpips.distance(image, torch::rand({3, 40, 41}));
            }).find("differ in size (3x40x40 and 3x40x41)"),
            std::string::npos);
  EXPECT_NE(error_message([&] { lpips.distance(image[0], image[0]); }).find("got 40x40"),
            std::string::npos);
  const int small = lpips.min_size() - 1;
  const auto tiny = torch::rand({3, small, 64});
  EXPECT_NE(error_message([&] { lpips.distance(tiny, tiny); }).find("too small"),
            std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Backbones, LpipsFixture, ::testing::Values(LpipsNet::Alex, LpipsNet::Vgg),
                         [](const auto& info) { return std::string(lpips_net_name(info.param)); });

// 3DGS's and Mip-Splatting's metrics give the official VGG metric [0, 1] images where it expects
// [-1, 1]: the official distance of the images (x + 1) / 2, which map back to x.
TEST(Lpips, Vgg3dgsIsTheOfficialVggOfImagesTakenInMinusOneToOne) {
  if (!fs::exists(kHeads)) GTEST_SKIP() << "LPIPS heads not found: " << kHeads;
  const Lpips official = stand_in_lpips(LpipsNet::Vgg);
  const Lpips as_3dgs = stand_in_lpips(LpipsNet::Vgg3dgs);
  for (const auto& [a, b] : fixture_pairs()) {
    const float distance = as_3dgs.distance(a, b);
    EXPECT_NEAR(distance, official.distance((a + 1) / 2, (b + 1) / 2), 1e-5);
    EXPECT_GT(std::abs(distance - official.distance(a, b)), 1e-3);  // a different number
  }
  EXPECT_EQ(default_lpips_weights(LpipsNet::Vgg3dgs).heads,
            default_lpips_weights(LpipsNet::Vgg).heads);
}

TEST(Lpips, RunsAtItsMinimumSize) {
  if (!fs::exists(kHeads)) GTEST_SKIP() << "LPIPS heads not found: " << kHeads;
  for (LpipsNet net : {LpipsNet::Alex, LpipsNet::Vgg}) {
    Lpips lpips = stand_in_lpips(net);
    const auto image = torch::rand({3, lpips.min_size(), lpips.min_size()});
    const float distance = lpips.distance(image, image.flip(2));
    EXPECT_GT(distance, 0.f) << lpips_net_name(net);  // a mirrored noise image differs
    EXPECT_TRUE(std::isfinite(distance)) << lpips_net_name(net);
  }
}

// A view smaller than the network takes still gets PSNR and SSIM; the report says why it has no
// LPIPS, and the mean has none.
TEST(Lpips, ViewsUnderItsSizeAreScoredWithoutIt) {
  if (!fs::exists(kHeads)) GTEST_SKIP() << "LPIPS heads not found: " << kHeads;
  LoadedLpips loaded{stand_in_lpips(LpipsNet::Alex), "alex"};
  const int size = loaded.get()->min_size();
  Image small(size - 1, size + 5, 3), large(size, size, 3);
  for (float& value : small.data) value = 0.5f;
  for (float& value : large.data) value = 0.5f;
  const std::vector<ViewMetrics> views = {measure_view("large", large, large, loaded.get()),
                                          measure_view("small", small, small, loaded.get())};
  EXPECT_TRUE(views[0].lpips.has_value());
  EXPECT_FALSE(views[1].lpips.has_value());
  EXPECT_TRUE(std::isinf(views[1].psnr));
  EXPECT_EQ(lpips_status(loaded, views),
            "alex: not computed for views under 31x31 pixels, the network's smallest");
  EXPECT_EQ(lpips_status(loaded, {views[0]}), "alex");
}

TEST(Lpips, ErrorsNameTheCheckpointAndTheEntry) {
  if (!fs::exists(kHeads)) GTEST_SKIP() << "LPIPS heads not found: " << kHeads;
  const fs::path alex_heads = heads_file(LpipsNet::Alex);
  const std::string not_a_backbone = error_message([&] {
    Lpips::load(LpipsNet::Alex, {alex_heads, alex_heads});
  });
  EXPECT_EQ(not_a_backbone.rfind(alex_heads.string() + ": ", 0), 0u) << not_a_backbone;
  EXPECT_NE(not_a_backbone.find("missing 'features.0."), std::string::npos) << not_a_backbone;

  const std::string wrong_heads = error_message([&] {
    Lpips::from_state_dicts(LpipsNet::Vgg, stand_in_backbone(LpipsNet::Vgg),
                            priors::read_state_dict(alex_heads), {"vgg16.pth", alex_heads});
  });
  EXPECT_EQ(wrong_heads.rfind(alex_heads.string() + ": ", 0), 0u) << wrong_heads;
  EXPECT_NE(wrong_heads.find("lin1.model.1.weight"), std::string::npos) << wrong_heads;

  testing::TempDir dir;
  const std::string missing = error_message([&] {
    Lpips::load(LpipsNet::Vgg, {dir / "none.pth", alex_heads});
  });
  EXPECT_EQ(missing.rfind((dir / "none.pth").string() + ": ", 0), 0u) << missing;
}

TEST(Lpips, ParsesTheOfficialNetworkNames) {
  EXPECT_EQ(parse_lpips_net("alex"), LpipsNet::Alex);
  EXPECT_EQ(parse_lpips_net("vgg"), LpipsNet::Vgg);
  EXPECT_EQ(parse_lpips_net("vgg-3dgs"), LpipsNet::Vgg3dgs);
  EXPECT_EQ(lpips_net_name(LpipsNet::Vgg3dgs), std::string("vgg-3dgs"));
  EXPECT_NE(error_message([] { parse_lpips_net("squeeze"); }).find("'squeeze'"), std::string::npos);
}

// Sets an environment variable (or unsets it for nullopt) for one scope.
TEST(Lpips, DefaultWeightsFollowTheWeightsDirectoryThenTorchsCache) {
  testing::TempDir models;
  ScopedEnv torch_home("TORCH_HOME", "/cache/torch");
  {
    ScopedEnv weights("IESRGS_WEIGHTS_DIR", models.path().string());
    const LpipsWeights vgg = default_lpips_weights(LpipsNet::Vgg);
    EXPECT_EQ(vgg.backbone, fs::path("/cache/torch/hub/checkpoints/vgg16-397923af.pth"));
    EXPECT_EQ(vgg.heads, models / "lpips/v0.1/vgg.pth");
    testing::write_text(models / "vgg16-397923af.pth", "x");
    EXPECT_EQ(default_lpips_weights(LpipsNet::Vgg).backbone, models / "vgg16-397923af.pth");
  }
  ScopedEnv no_weights("IESRGS_WEIGHTS_DIR", std::nullopt);
  const LpipsWeights alex = default_lpips_weights(LpipsNet::Alex);
  EXPECT_EQ(alex.backbone, fs::path("/cache/torch/hub/checkpoints/alexnet-owt-7be5be79.pth"));
  // The development data's copy, found from any working directory.
  EXPECT_EQ(alex.heads, priors::default_weights_dir() / "lpips/v0.1/alex.pth");
  EXPECT_TRUE(alex.heads.is_absolute()) << alex.heads;
}

TEST(Lpips, UnavailableReasonNamesTheMissingFile) {
  testing::TempDir dir;
  testing::write_text(dir / "backbone.pth", "x");
  testing::write_text(dir / "heads.pth", "x");
  EXPECT_EQ(lpips_unavailable_reason(LpipsNet::Alex, {dir / "backbone.pth", dir / "heads.pth"}),
            std::nullopt);
  EXPECT_EQ(
      lpips_unavailable_reason(LpipsNet::Vgg, {dir / "none.pth", dir / "heads.pth"}),
      (dir / "none.pth").string() + ": no such file (torchvision's ImageNet VGG16 checkpoint)");
  EXPECT_EQ(lpips_unavailable_reason(LpipsNet::Alex, {dir / "backbone.pth", dir / "none.pth"}),
            (dir / "none.pth").string() + ": no such file (LPIPS v0.1 alex linear heads)");
}

}  // namespace
}  // namespace iesrgs::eval
