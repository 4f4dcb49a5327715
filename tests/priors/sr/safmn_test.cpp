#include "priors/sr/safmn.hpp"

#include <gtest/gtest.h>

#include "priors/sr/sr_test_support.hpp"
#include "support/expect_error.hpp"
#include "support/module_shapes.hpp"

namespace iesrgs::priors::sr {
namespace {

using iesrgs::testing::contains;
using iesrgs::testing::error_message;
using iesrgs::testing::parameter_shapes;
using iesrgs::testing::read_parameter_shapes;
using iesrgs::testing::zero_state_dict;
using sr_testing::kFixtures;
using sr_testing::kReleasedWeights;
using sr_testing::lego_crop;
using sr_testing::max_abs_difference;
using sr_testing::read_npy_tensor;

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

// SAFMN_DF2K_x3.pth's layout and the large model's (SAFMN_L_*): the configuration is read back
// from the names and shapes alone, and builds exactly that layout.
TEST(Safmn, InfersThePaperModelsFromTheirLayout) {
  struct Released {
    const char* names;
    int64_t dim, blocks, scale;
  };
  for (const Released& released : {Released{"safmn_df2k_x3_names.txt", 36, 8, 3},
                                   Released{"safmn_l_x4_names.txt", 128, 16, 4}}) {
    SCOPED_TRACE(released.names);
    const iesrgs::testing::ParameterShapes official =
        read_parameter_shapes(kFixtures / released.names);
    const SafmnOptions options = infer_safmn_options(zero_state_dict(official), "net.pth");
    EXPECT_EQ(options.release, SafmnRelease::Iccv2023);
    EXPECT_EQ(options.dim, released.dim);
    EXPECT_EQ(options.blocks, released.blocks);
    EXPECT_EQ(options.scale, released.scale);
    Safmn net(options);
    EXPECT_EQ(parameter_shapes(*net), official);
  }
}

// Tiny seeded networks of both releases, loaded by name only: the layout comes from the file.
TEST(Safmn, LoadsEitherReleaseAsTheOfficialModuleComputesIt) {
  for (const char* name : {"tiny_safmn_x2", "tiny_safmn_iccv_x2"}) {
    SCOPED_TRACE(name);
    const auto net = make_sr_net("safmn", kFixtures / (std::string(name) + ".pth"), 2);
    EXPECT_LT(max_abs_difference(net->upscale(lego_crop()),
                                 read_npy_tensor(kFixtures / (std::string(name) + "_lego.npy"))),
              1e-5);
  }
}

TEST(Safmn, PaperModelsPadInputsBelowTheirShallowerPyramid) {
  const auto net = make_sr_net("safmn", kFixtures / "tiny_safmn_iccv_x2.pth", 2);
  const torch::Tensor out = net->upscale(lego_crop().narrow(2, 0, 5).narrow(3, 0, 7).contiguous());
  EXPECT_EQ(out.sizes(), torch::IntArrayRef({1, 3, 10, 14}));
  EXPECT_EQ(safmn_min_side(SafmnRelease::Iccv2023), 8);
  EXPECT_EQ(safmn_min_side(SafmnRelease::Ntire2023), 16);
}

TEST(Safmn, RefusesAnotherScaleOrNetworkNamingTheFile) {
  const auto tiny = kFixtures / "tiny_safmn_iccv_x2.pth";
  const std::string scale = error_message([&] { make_sr_net("safmn", tiny, 4); });
  EXPECT_TRUE(contains(scale, tiny.string() + ": a x2 SAFMN checkpoint, but x4")) << scale;
  const auto imdn = kFixtures / "tiny_imdn_x2.pth";
  const std::string other = error_message([&] { make_sr_net("safmn", imdn, 2); });
  EXPECT_TRUE(contains(other, imdn.string() + ": not an RGB SAFMN checkpoint")) << other;
  StateDict unnormalized = read_state_dict(tiny);
  unnormalized.erase("feats.0.norm1.weight");
  const std::string layout = error_message([&] { infer_safmn_options(unnormalized, "odd.pth"); });
  EXPECT_TRUE(contains(layout, "odd.pth: a SAFMN checkpoint of neither released layout")) << layout;
}

}  // namespace
}  // namespace iesrgs::priors::sr
