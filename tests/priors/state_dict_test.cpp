#include "priors/state_dict.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "io/atomic_file.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::priors {
namespace {

namespace fs = std::filesystem;
using testing::error_message;
using testing::TempDir;
using testing::write_text;

const fs::path kFixtures = fs::path(IESRGS_TEST_DATA) / "priors" / "state_dict";
const fs::path kWeights = fs::path(IESRGS_SHARED_DATA) / "weights";

// The tensors make_fixtures.py writes into every mixed_*.pth, recomputed here.
StateDict expected_mixed() {
  const torch::Tensor base = torch::arange(12, torch::kFloat).reshape({3, 4}) + 100;
  return {
      {"conv.weight", torch::arange(24, torch::kFloat).reshape({2, 3, 2, 2}) - 12},
      {"half", torch::arange(6, torch::kFloat) / 4},
      {"double", (torch::arange(5, torch::kDouble) / 3).to(torch::kFloat)},
      {"bfloat16", torch::arange(4, torch::kFloat) * 0.5},
      {"base", base},
      {"transposed", base.t().contiguous()},
      {"strided", base.slice(0, 1).slice(1, 0, 4, 2).contiguous()},
      {"bn.num_batches_tracked", torch::tensor(int64_t{7})},
      {"scalar", torch::tensor(2.5f)},
      {"empty", torch::zeros({0, 3})},
  };
}

void expect_same(const StateDict& actual, const StateDict& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (const auto& [name, tensor] : expected) {
    SCOPED_TRACE(name);
    ASSERT_EQ(actual.count(name), 1u);
    const torch::Tensor& got = actual.at(name);
    EXPECT_TRUE(got.is_contiguous());
    EXPECT_EQ(got.scalar_type(), tensor.scalar_type());
    EXPECT_EQ(got.sizes(), tensor.sizes());
    EXPECT_TRUE(torch::equal(got, tensor));
  }
}

class MixedContainers : public ::testing::TestWithParam<const char*> {};

TEST_P(MixedContainers, ReadsExactValues) {
  expect_same(read_state_dict(kFixtures / (std::string("mixed_") + GetParam() + ".pth")),
              expected_mixed());
}

INSTANTIATE_TEST_SUITE_P(StateDict, MixedContainers,
                         ::testing::Values("zip", "legacy", "zip_protocol5", "legacy_protocol4",
                                           "deflated", "zip64"));

TEST(StateDict, PrefersEmaWeightsAndIgnoresOtherEntries) {
  expect_same(read_state_dict(kFixtures / "wrapped.pth"), {{"w", torch::ones({2})}});
}

// The layout of the Python model that make_fixtures.py saves.
struct ConvBn : torch::nn::Module {
  ConvBn()
      : conv(register_module("conv", torch::nn::Conv2d(3, 4, 3))),
        bn(register_module("bn", torch::nn::BatchNorm2d(4))) {}
  torch::nn::Conv2d conv;
  torch::nn::BatchNorm2d bn;
};

TEST(StateDict, StripsModulePrefixAndLoadsStrictly) {
  const fs::path file = kFixtures / "module_legacy.pth";
  const StateDict weights = read_state_dict(file);
  ASSERT_EQ(weights.size(), 7u);
  ConvBn model;
  load_state_dict(model, weights, file);
  EXPECT_TRUE(torch::equal(model.conv->weight,
                           torch::arange(108, torch::kFloat).reshape({4, 3, 3, 3}) * 0.25f));
  EXPECT_TRUE(torch::equal(model.bn->running_var, torch::arange(4, torch::kFloat) * 0.25f + 5));
  EXPECT_EQ(model.bn->num_batches_tracked.item<int64_t>(), 11);
}

TEST(StateDict, StrictLoadNamesTheFirstBadEntry) {
  const fs::path file = kFixtures / "module_legacy.pth";
  const StateDict weights = read_state_dict(file);
  ConvBn model;

  StateDict missing = weights;
  missing.erase("bn.bias");
  EXPECT_EQ(error_message([&] { load_state_dict(model, missing, file); }),
            file.string() + ": missing 'bn.bias' [4]");

  StateDict unexpected = weights;
  unexpected["extra.weight"] = torch::zeros({1});
  EXPECT_EQ(error_message([&] { load_state_dict(model, unexpected, file); }),
            file.string() + ": unexpected 'extra.weight'");

  StateDict misshaped = weights;
  misshaped["conv.bias"] = torch::zeros({5});
  EXPECT_EQ(error_message([&] { load_state_dict(model, misshaped, file); }),
            file.string() + ": 'conv.bias' has shape [5] in the file but [4] in the model");

  StateDict diverged = weights;
  diverged["bn.running_var"] = weights.at("bn.running_var").clone();
  diverged["bn.running_var"][2] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(error_message([&] { load_state_dict(model, diverged, file); }),
            file.string() + ": 'bn.running_var' holds non-finite values (NaN or infinity)");
}

struct SharedCheckpoint {
  const char* file;
  size_t count;
  const char* name;
  std::vector<int64_t> shape;
  std::vector<float> first_values;
  double sum;
};

class SharedCheckpoints : public ::testing::TestWithParam<SharedCheckpoint> {};

// Key counts, shapes, values and sums as PyTorch's torch.load reports them.
TEST_P(SharedCheckpoints, ReadLikeTorchLoad) {
  const SharedCheckpoint& expected = GetParam();
  const fs::path file = kWeights / expected.file;
  if (!fs::exists(file)) GTEST_SKIP() << "shared weights absent: " << file;
  const StateDict weights = read_state_dict(file);
  EXPECT_EQ(weights.size(), expected.count);
  ASSERT_EQ(weights.count(expected.name), 1u);
  const torch::Tensor tensor = weights.at(expected.name);
  EXPECT_EQ(tensor.sizes(), torch::IntArrayRef(expected.shape));
  for (size_t i = 0; i < expected.first_values.size(); ++i)
    EXPECT_EQ(tensor.flatten()[i].item<float>(), expected.first_values[i]);
  double sum = 0;
  for (const auto& [name, value] : weights) sum += value.to(torch::kDouble).sum().item<double>();
  EXPECT_NEAR(sum, expected.sum, 1e-9 * std::abs(expected.sum));
}

INSTANTIATE_TEST_SUITE_P(
    StateDict, SharedCheckpoints,
    ::testing::Values(SharedCheckpoint{"sr/IMDN_x4.pth",
                                       92,
                                       "fea_conv.bias",
                                       {64},
                                       {0.008921879343688488f, 0.004473275505006313f},
                                       -1442.9472306299867},
                      SharedCheckpoint{"sr/PAN_x4.pth",
                                       146,
                                       "conv_first.bias",
                                       {40},
                                       {0.33232712745666504f, -0.01806573010981083f},
                                       -3805.333855866662},
                      SharedCheckpoint{"sr/SAFMN_x4.pth",
                                       62,
                                       "norm.beta",
                                       {1, 36, 1, 1},
                                       {0.07792212814092636f, -0.006987592205405235f},
                                       254.74551999574632},
                      SharedCheckpoint{"lpips/v0.1/alex.pth",
                                       5,
                                       "lin1.model.1.weight",
                                       {1, 192, 1, 1},
                                       {0.f, 0.f},
                                       105.2753545809201},
                      SharedCheckpoint{"lpips/v0.1/squeeze.pth",
                                       7,
                                       "lin1.model.1.weight",
                                       {1, 128, 1, 1},
                                       {2.3874137696111575e-05f, 7.057860057102516e-05f},
                                       173.4387181383333},
                      SharedCheckpoint{"lpips/v0.1/vgg.pth",
                                       5,
                                       "lin1.model.1.weight",
                                       {1, 128, 1, 1},
                                       {0.039409372955560684f, 0.47568023204803467f},
                                       131.85550854727626}));

TEST(StateDict, RejectsFilesThatAreNoCheckpoint) {
  TempDir dir;
  write_text(dir / "text.pth", "hello");
  EXPECT_EQ(error_message([&] { read_state_dict(dir / "text.pth"); }),
            (dir / "text.pth").string() +
                ": not a PyTorch checkpoint (neither zip nor legacy torch.save)");
  EXPECT_NE(error_message([&] { read_state_dict(dir / "absent.pth"); }).find("absent.pth"),
            std::string::npos);
}

// Every truncation must fail, and every single-byte corruption either load or fail, with an Error
// that names the source: never a crash, a hang or an exception of another type.
void expect_robust(const fs::path& good) {
  const std::string bytes = read_file(good);
  const auto check = [&](std::string_view contents, bool must_fail) {
    try {
      parse_state_dict(contents, "bad.pth");
      EXPECT_FALSE(must_fail);
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("bad.pth: ", 0), 0u) << e.what();
    }
  };
  for (size_t length = 0; length < bytes.size(); ++length) {
    SCOPED_TRACE("truncated to " + std::to_string(length));
    check(std::string_view(bytes).substr(0, length), true);
  }
  for (size_t at = 0; at < bytes.size(); ++at) {
    SCOPED_TRACE("corrupted at " + std::to_string(at));
    std::string corrupt = bytes;
    corrupt[at] = static_cast<char>(corrupt[at] ^ 0x5a);
    check(corrupt, false);
  }
}

TEST(StateDict, SurvivesTruncationAndCorruption) {
  for (const char* name :
       {"mixed_zip.pth", "mixed_legacy.pth", "mixed_zip64.pth", "mixed_deflated.pth"})
    expect_robust(kFixtures / name);
}

TEST(StateDict, ZipChecksumCatchesCorruptWeights) {
  std::string bytes = read_file(kFixtures / "mixed_zip.pth");
  const size_t value = bytes.find(std::string("\x00\x00\xc8\x42", 4));  // 100.f opens "base"
  ASSERT_NE(value, std::string::npos);
  bytes[value + 3] = 0x43;
  EXPECT_EQ(error_message([&] { parse_state_dict(bytes, "flipped.pth"); }),
            "flipped.pth: zip member 'archive/data/4' fails its CRC");
}

}  // namespace
}  // namespace iesrgs::priors
