#include "priors/sr/registry.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <optional>

#include "priors/sr/esrgan.hpp"
#include "priors/sr/sr_test_support.hpp"
#include "support/expect_error.hpp"
#include "support/scoped_env.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::priors::sr {
namespace {

using iesrgs::testing::contains;
using iesrgs::testing::error_message;
using iesrgs::testing::ScopedEnv;
using iesrgs::testing::TempDir;
using iesrgs::testing::write_text;

TEST(SrRegistry, KnowsTheBuiltInModels) {
  const std::vector<std::string>& names = sr_model_names();
  for (const char* model : {"bicubic", "safmn", "imdn", "pan", "swinir", "esrgan-slim",
                            "esrgan-medium", "esrgan-thick"})
    EXPECT_NE(std::find(names.begin(), names.end(), model), names.end()) << model;
  const auto net = make_sr_net("bicubic", {}, 4);
  EXPECT_EQ(net->name(), "bicubic");
  EXPECT_EQ(net->scale(), 4);
}

TEST(SrRegistry, UnknownModelAndBadScaleAreErrors) {
  const std::string unknown = error_message([] { make_sr_net("edsr", {}, 4); });
  EXPECT_TRUE(contains(unknown, "'edsr'") && contains(unknown, "safmn")) << unknown;
  EXPECT_EQ(error_message([] { make_sr_net("pan", {}, 0); }), "pan: invalid scale 0");
}

TEST(SrRegistry, ReadsTheScaleThatACheckpointsNameStates) {
  const std::map<std::string, int> names = {{"PANx2_DF2K.pth", 2},    {"IMDN_x4.pth", 4},
                                            {"SAFMN_DF2K_x3.pth", 3}, {"dir_x2/x8.pth", 8},
                                            {"max3.pth", 0},          {"model.pth", 0},
                                            {"a_x2_then_x4.pth", 0},  {"PAN_x12.pth", 0},
                                            {"PAN_64x3.pth", 0},      {"tuned_x4_again_x4.pth", 4}};
  for (const auto& [name, scale] : names) EXPECT_EQ(scale_in_file_name(name), scale) << name;
}

// PAN's x2 and x3 files share one layout: only the name can stop one running at the other's scale.
TEST(SrRegistry, RefusesACheckpointWhoseNameStatesAnotherScale) {
  const auto file = sr_testing::kFixtures / "tiny_pan_x2.pth";
  const std::string message = error_message([&] { make_sr_net("pan", file, 3); });
  EXPECT_TRUE(contains(message, file.string() + ": its name says x2, but x3 was requested"))
      << message;
}

TEST(SrRegistry, DefaultWeightsFollowTheEnvironment) {
  ScopedEnv weights("IESRGS_WEIGHTS_DIR", "/opt/weights");
  EXPECT_EQ(default_sr_weights("safmn", 4), "/opt/weights/sr/SAFMN_x4.pth");
  EXPECT_EQ(default_sr_weights("pan", 2), "/opt/weights/sr/PAN_x2.pth");
}

TEST(SrRegistry, DefaultWeightsAreTheDevelopmentDataOtherwise) {
  ScopedEnv weights("IESRGS_WEIGHTS_DIR", std::nullopt);
  EXPECT_EQ(default_sr_weights("safmn", 4),
            std::filesystem::path(IESRGS_SHARED_DATA) / "weights" / "sr" / "SAFMN_x4.pth");
}

TEST(SrRegistry, AutoPicksSafmnThenTheBestInstalledEsrganThenBicubic) {
  TempDir weights_dir, npm_dir;
  ScopedEnv weights("IESRGS_WEIGHTS_DIR", weights_dir.path().string());
  ScopedEnv npm("IESRGS_NPM_DIR", npm_dir.path().string());
  EXPECT_EQ(auto_sr_model(4), "bicubic");
  write_text(default_esrgan_package_dir("slim") / "models/x4/model.json", "{}");
  EXPECT_EQ(auto_sr_model(4), "esrgan-slim");
  write_text(default_esrgan_package_dir("thick") / "models/x4/model.json", "{}");
  EXPECT_EQ(auto_sr_model(4), "esrgan-thick");
  EXPECT_EQ(auto_sr_model(2), "bicubic");
  write_text(default_sr_weights("safmn", 4), "");
  EXPECT_EQ(auto_sr_model(4), "safmn");
}

TEST(SrRegistry, MissingDefaultWeightsSayWhereTheyWereLookedFor) {
  TempDir dir;
  ScopedEnv weights("IESRGS_WEIGHTS_DIR", dir.path().string());
  const std::string message = error_message([] { make_sr_net("imdn", {}, 4); });
  EXPECT_TRUE(contains(message, (dir / "sr" / "IMDN_x4.pth").string())) << message;
  EXPECT_TRUE(contains(message, "IESRGS_WEIGHTS_DIR")) << message;
}

TEST(SrRegistry, CheckpointOfAnotherConfigurationNamesTheFile) {
  const auto file = sr_testing::kFixtures / "tiny_pan_x2.pth";
  const std::string message = error_message([&] { make_sr_net("pan", file, 4); });
  EXPECT_TRUE(contains(message, file.string())) << message;
}

TEST(SrRegistry, NetworksRejectInputsThatAreNotRgbBatches) {
  const auto file = sr_testing::kReleasedWeights / "PAN_x4.pth";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not found (shared data absent)";
  const auto net = make_sr_net("pan", file, 4);
  EXPECT_EQ(error_message([&] {
              net->upscale(torch::zeros({3, 8, 8}));
            }),
            "pan: expected an RGB batch of shape (1, 3, H, W), got [3, 8, 8]");
}

// The x4 benchmark protocol on lego test views, per backend. A measurement rather than a check
// (seconds of CPU per view and network): run it with --gtest_also_run_disabled_tests.
TEST(SrMeasurement, DISABLED_LegoTestViewPsnr) {
  if (!std::filesystem::exists(default_sr_weights("safmn", 4)))
    GTEST_SKIP() << default_sr_weights("safmn", 4) << " not found (shared data absent)";
  const std::vector<int> views = {0, 20, 40, 60, 80, 100, 120, 140, 160, 180};
  std::map<std::string, double> mean;
  for (const std::string model : {"bicubic", "safmn", "imdn", "pan"}) {
    const auto net = make_sr_net(model, {}, 4);
    for (const int index : views) {
      const sr_testing::ProtocolView view = sr_testing::lego_test_view(index);
      mean[model] += sr_testing::psnr(net->upscale(view.low), view.high) / double(views.size());
    }
    std::printf("%-8s %.2f dB mean over %zu lego test views\n", model.c_str(), mean[model],
                views.size());
  }
  for (const char* model : {"safmn", "imdn", "pan"})
    EXPECT_GT(mean[model], mean["bicubic"] + 3) << model;
}

}  // namespace
}  // namespace iesrgs::priors::sr
