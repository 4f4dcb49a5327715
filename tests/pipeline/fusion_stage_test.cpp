#include "pipeline/fusion_stage.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include "io/image.hpp"
#include "io/npy.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::contains;
using testing::error_message;

// One 8x6 HR view's references on disk: E_image dark, I_image bright, both depth maps.
struct References {
  testing::TempDir dir;
  ReferenceFiles files{dir / "e.png", dir / "e.npy", dir / "i.png", dir / "i.npy"};
  Camera camera;

  References() {
    camera.name = "v";
    camera.intrinsics = {8, 6, 10, 10, 4, 3};
    Image8 dark(8, 6, 3), bright(8, 6, 3);
    std::fill(bright.data.begin(), bright.data.end(), 255);
    write_png(files.external_image, dark);
    write_png(files.internal_image, bright);
    write_npy(files.external_disparity, std::vector<float>(48, 0.5f), {6, 8});
    write_npy(files.internal_depth, std::vector<float>(48, 2.0f), {6, 8});
  }
};

TEST(FusionStage, LoadsWhatTheLossUsesAndTheMaskFromTheDiscrepancy) {
  const References refs;
  loss::FusionWeights weights;  // IE-SRGS: masked texture, both depth terms
  const loss::FusionTargets all = load_fusion_targets(refs.files, refs.camera, weights, 0.6);
  ASSERT_TRUE(all.external_image.defined() && all.internal_image.defined());
  EXPECT_EQ(all.external_image.sizes(), (std::vector<int64_t>{3, 6, 8}));
  EXPECT_FLOAT_EQ(all.internal_depth[0][0].item<float>(), 2.0f);
  EXPECT_FLOAT_EQ(all.external_disparity[5][7].item<float>(), 0.5f);
  EXPECT_TRUE((all.external_image == 0).all().item<bool>());
  EXPECT_TRUE((all.internal_image == 1).all().item<bool>());
  // D = |1 - 0| / (1 + 1e-6), just under 1: at or over T = 0.6, under T = 1.
  EXPECT_EQ(all.internal_share.sizes(), (std::vector<int64_t>{6, 8}));
  EXPECT_TRUE((all.internal_share == 1).all().item<bool>());
  const loss::FusionTargets strict = load_fusion_targets(refs.files, refs.camera, weights, 1.0);
  EXPECT_TRUE((strict.internal_share == 0).all().item<bool>());

  weights.texture = loss::TextureGuidance::Average;
  const loss::FusionTargets average = load_fusion_targets(refs.files, refs.camera, weights, 0.6);
  EXPECT_TRUE((average.internal_share == 0.5).all().item<bool>());

  weights.texture = loss::TextureGuidance::External;
  weights.internal_depth = 0;
  const loss::FusionTargets external = load_fusion_targets(refs.files, refs.camera, weights, 0.6);
  EXPECT_FALSE(external.internal_image.defined());
  EXPECT_FALSE(external.internal_depth.defined());
  EXPECT_TRUE(external.external_disparity.defined());
}

TEST(FusionStage, MissingOrMisfitReferencesNameTheViewOrTheFile) {
  References refs;
  ReferenceFiles lacking = refs.files;
  lacking.internal_image.clear();
  EXPECT_TRUE(contains(
      error_message([&] { load_fusion_targets(lacking, refs.camera, loss::FusionWeights{}, 0.6); }),
      "view v: the loss needs the internal image, which this run lacks"));
  write_png(refs.files.internal_image, Image8(4, 3, 3));
  const std::string small = error_message(
      [&] { load_fusion_targets(refs.files, refs.camera, loss::FusionWeights{}, 0.6); });
  EXPECT_TRUE(
      contains(small, refs.files.internal_image.string() + ": is 4x3, the HR camera is 8x6"))
      << small;
  write_png(refs.files.internal_image, Image8(8, 6, 3));
  write_npy(refs.files.internal_depth, std::vector<float>(12, 1.0f), {3, 4});
  const std::string map = error_message(
      [&] { load_fusion_targets(refs.files, refs.camera, loss::FusionWeights{}, 0.6); });
  EXPECT_TRUE(contains(map, refs.files.internal_depth.string() + ": is not a 6x8")) << map;
}

}  // namespace
}  // namespace iesrgs::pipeline
