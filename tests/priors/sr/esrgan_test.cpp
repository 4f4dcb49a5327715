#include "priors/sr/esrgan.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "eval/metrics.hpp"
#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "io/image_tensor.hpp"
#include "io/resize.hpp"
#include "priors/keras_model.hpp"
#include "support/expect_error.hpp"
#include "support/scoped_env.hpp"
#include "support/temp_dir.hpp"
#include "support/tensor_files.hpp"

namespace iesrgs::priors::sr {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using iesrgs::testing::error_message;
using iesrgs::testing::max_abs_difference;
using iesrgs::testing::ScopedEnv;
using iesrgs::testing::TempDir;
using iesrgs::testing::write_text;

const fs::path kEsrganFixtures = fs::path(IESRGS_TEST_DATA) / "priors" / "esrgan";

// An NHWC array written by make_fixtures.js, as an NCHW tensor.
torch::Tensor read_nchw(const fs::path& file) {
  return iesrgs::testing::read_npy_tensor(file).permute({0, 3, 1, 2}).contiguous();
}

TEST(KerasModel, MatchesTensorFlowJs) {
  const auto model = keras::LayersModel::load(kEsrganFixtures / "tiny" / "model.json");
  const torch::Tensor output = model.forward(read_nchw(kEsrganFixtures / "tiny_input.npy"));
  EXPECT_LT(max_abs_difference(output, read_nchw(kEsrganFixtures / "tiny_output.npy")), 1e-5);
}

// A copy of the tiny model whose model.json `edit` changed, and the error loading it gives.
template <typename Edit>
std::string load_error(Edit edit) {
  TempDir dir;
  for (const auto& entry : fs::directory_iterator(kEsrganFixtures / "tiny"))
    fs::copy_file(entry.path(), dir / entry.path().filename().string());
  json model = json::parse(read_file(dir / "model.json"));
  edit(model, dir);
  write_text(dir / "model.json", model.dump());
  const std::string message = error_message([&] { keras::LayersModel::load(dir / "model.json"); });
  const std::string prefix = (dir / "model.json").string() + ": ";
  EXPECT_EQ(message.rfind(prefix, 0), 0u) << message;
  return message.substr(std::min(prefix.size(), message.size()));
}

json& layer(json& model, size_t index) {
  return model["modelTopology"]["config"]["layers"][index];
}

json& first_weight(json& model) {
  return model["weightsManifest"][0]["weights"][0];
}

TEST(KerasModel, NamesTheProblemWithABrokenModel) {
  EXPECT_EQ(load_error([](json& m, const TempDir&) { layer(m, 2)["class_name"] = "Dropout"; }),
            "layer 'F_1_Relu': unsupported layer class 'Dropout'");
  EXPECT_EQ(load_error([](json& m, const TempDir&) {
              layer(m, 1)["config"]["strides"] = {2, 2};
            }),
            "layer 'F_1': unsupported strides [2,2]");
  EXPECT_EQ(load_error([](json& m, const TempDir&) { layer(m, 1)["config"]["filters"] = 5; }),
            "layer 'F_1': weight 'F_1/kernel' has shape [3, 3, 3, 6], expected [3, 3, 3, 5]");
  EXPECT_EQ(
      load_error([](json& m, const TempDir&) { layer(m, 4)["inbound_nodes"][0][1][0] = "Later"; }),
      "layer 'Concat': unknown input [\"Later\",0,0,{}]");
  EXPECT_EQ(load_error([](json& m, const TempDir&) {
              first_weight(m)["quantization"] = {{"dtype", "uint8"}};
            }),
            "weight 'F_1/kernel' is quantized (unsupported)");
  EXPECT_EQ(load_error([](json& m, const TempDir&) {
              first_weight(m)["shape"] = {3, 3, 3, 600};
            }),
            "weight 'F_1/kernel' extends past the end of its shards");
  EXPECT_EQ(load_error([](json&, const TempDir& dir) {
              write_text(dir / "group1-shard2of2.bin",
                         read_file(dir / "group1-shard2of2.bin") + "x");
            }),
            "weight shards hold more data than the manifest lists");
  EXPECT_EQ(load_error([](json&, const TempDir& dir) {
              std::string shard = read_file(dir / "group1-shard1of2.bin");
              const float nan = std::numeric_limits<float>::quiet_NaN();
              shard.replace(0, sizeof nan, reinterpret_cast<const char*>(&nan), sizeof nan);
              write_text(dir / "group1-shard1of2.bin", shard);
            }),
            "weight 'F_1/kernel' holds non-finite values (NaN or infinity)");
}

TEST(KerasModel, NamesAMissingShardOrInvalidJson) {
  TempDir dir;
  fs::copy_file(kEsrganFixtures / "tiny" / "model.json", dir / "model.json");
  EXPECT_EQ(error_message([&] {
              keras::LayersModel::load(dir / "model.json");
            }).find((dir / "group1-shard1of2.bin").string()),
            0u);
  write_text(dir / "model.json", "{\"modelTopology\": ");
  EXPECT_EQ(error_message([&] {
              keras::LayersModel::load(dir / "model.json");
            }).rfind((dir / "model.json").string() + ": malformed model: ", 0),
            0u);
}

fs::path slim_package() {
  return default_esrgan_package_dir("slim");
}

TEST(Esrgan, SlimX4MatchesTensorFlowJs) {
  if (!fs::exists(slim_package())) GTEST_SKIP() << "esrgan-slim absent: " << slim_package();
  const auto net = make_esrgan("slim", 4, {});
  EXPECT_EQ(net->name(), "esrgan-slim");
  EXPECT_EQ(net->scale(), 4);
  // The fixture holds the model's own 0..255 values; upscale works in 0..1 and clips.
  const torch::Tensor input = read_nchw(kEsrganFixtures / "slim_x4_input.npy") / 255;
  const torch::Tensor expected =
      (read_nchw(kEsrganFixtures / "slim_x4_output.npy") / 255).clamp(0, 1);
  EXPECT_LT(max_abs_difference(net->upscale(input), expected), 1e-4);
}

TEST(Esrgan, RejectsUnknownVariantsScalesAndMissingPackages) {
  EXPECT_EQ(error_message([] { make_esrgan("huge", 4, {}); }),
            "unknown ESRGAN variant 'huge' (known: slim, medium, thick)");
  EXPECT_EQ(error_message([] { make_esrgan("slim", 5, {}); }),
            "esrgan-slim: no model for scale 5 (available: 2, 3, 4, 8)");
  TempDir dir;
  EXPECT_EQ(error_message([&] { make_esrgan("thick", 2, dir.path()); })
                .rfind((dir / "models" / "x2" / "model.json").string() +
                           ": esrgan-thick is not installed",
                       0),
            0u);
}

TEST(Esrgan, MissingPackageErrorSaysHowToInstallIt) {
  TempDir dir;
  const ScopedEnv npm_dir("IESRGS_NPM_DIR", dir.path().string());
  const std::string medium = error_message([] { make_esrgan("medium", 4, {}); });
  // One command for every package, setup's and those installed included: npm removes the
  // unsaved ones an install does not name.
  const std::string command = "npm install --prefix " + dir.path().string() +
                              " --no-save --omit=peer @upscalerjs/esrgan-slim@1.0.0 ";
  const std::string setup_packages = command + "@upscalerjs/esrgan-thick@1.0.0";
  EXPECT_NE(medium.find(command + "@upscalerjs/esrgan-medium@1.0.0 "
                                  "@upscalerjs/esrgan-thick@1.0.0 installs it)"),
            std::string::npos)
      << medium;
  EXPECT_EQ(medium.find("setup.sh"), std::string::npos) << medium;
  for (const char* variant : {"thick", "slim"}) {
    const std::string message = error_message([&] { make_esrgan(variant, 4, {}); });
    EXPECT_NE(message.find(setup_packages + " installs it, and so does scripts/setup.sh"),
              std::string::npos)
        << message;
  }
  // A medium package installed by hand stays named when thick is missing.
  std::filesystem::create_directories(dir / "node_modules" / "@upscalerjs" / "esrgan-medium");
  const std::string thick = error_message([] { make_esrgan("thick", 4, {}); });
  EXPECT_NE(thick.find("esrgan-medium@1.0.0 @upscalerjs/esrgan-thick@1.0.0 installs it"),
            std::string::npos)
      << thick;
}

TEST(Esrgan, PackageDirectoryFollowsTheEnvironment) {
  const ScopedEnv npm_dir("IESRGS_NPM_DIR", "/opt/models");
  EXPECT_EQ(default_esrgan_package_dir("medium"),
            fs::path("/opt/models/node_modules/@upscalerjs/esrgan-medium"));
}

struct LegoMargin {
  const char* variant;
  double decibels;  // measured on r_0: slim +0.16, medium +0.44, thick +1.50
};

void PrintTo(const LegoMargin& margin, std::ostream* out) {
  *out << margin.variant << " +" << margin.decibels << " dB";
}

class EsrganOnLego : public ::testing::TestWithParam<LegoMargin> {};

// The benchmark protocol: a Blender view composited on white, bicubic down x4, then back up.
TEST_P(EsrganOnLego, BeatsBicubicAtX4) {
  const fs::path view = fs::path(IESRGS_SHARED_DATA) / "nerf_synthetic/lego/test/r_0.png";
  const fs::path package = default_esrgan_package_dir(GetParam().variant);
  if (!fs::exists(view) || !fs::exists(package))
    GTEST_SKIP() << "needs " << view << " and " << package;
  const float white[3] = {1, 1, 1};
  const Image8 rgba = read_image8(view);
  const Image truth = composite_rgb(rgba, white);
  const Image low = composite_rgb(resize_bicubic(rgba, rgba.width / 4, rgba.height / 4), white);
  const auto net = make_esrgan(GetParam().variant, 4, {});
  const Image esrgan = to_image(net->upscale(to_tensor(low)));
  const Image bicubic = to_float(to_8bit(resize_bicubic(low, truth.width, truth.height)));
  EXPECT_GT(eval::psnr(esrgan, truth), eval::psnr(bicubic, truth) + GetParam().decibels);
}

INSTANTIATE_TEST_SUITE_P(Esrgan, EsrganOnLego,
                         ::testing::Values(LegoMargin{"slim", 0.1}, LegoMargin{"thick", 1.0}),
                         [](const auto& info) { return std::string(info.param.variant); });

}  // namespace
}  // namespace iesrgs::priors::sr
