#include "pipeline/evaluate.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "pipeline/render_views.hpp"
#include "support/one_gaussian.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::pipeline {
namespace {

namespace fs = std::filesystem;

// A scene of the one test view `camera`, whose ground truth `truth` is written into dir.
Scene one_view_scene(const fs::path& dir, Camera camera, const Image8& truth) {
  fs::create_directories(dir);
  camera.split = Split::Test;
  camera.image_path = dir / (camera.name + ".png");
  camera.stored = camera.intrinsics;
  write_png(camera.image_path, truth);
  Scene scene;
  scene.root = dir;
  scene.format = "blender";
  scene.cameras.push_back(camera);
  return scene;
}

eval::LoadedLpips no_lpips() {
  return eval::load_default_lpips("none");
}

TEST(Evaluate, WithoutGroundTruthOnlyRenders) {
  const testing::TempDir dir;
  const testing::OneGaussian one;
  const Evaluation evaluation =
      render_and_evaluate(one.model, {one.camera}, 8, {1, 1, 1}, nullptr, no_lpips(), dir / "test");
  EXPECT_TRUE(fs::exists(rendered_view_files(dir / "test", "v").rgb));
  // What eval needs to find the views: the split, and how it was held out.
  const auto record = nlohmann::json::parse(read_file(dir / "test" / "render.json"));
  EXPECT_EQ(record["split"], "test");
  EXPECT_EQ(record["test_every"], 8);
  EXPECT_TRUE(evaluation.report.views.empty());
  EXPECT_FALSE(fs::exists(dir / "test" / "metrics.json"));
  EXPECT_GT(evaluation.seconds_per_view, 0);
}

TEST(Evaluate, ScoresTheRendersAsWrittenAgainstTheTruth) {
  const testing::TempDir dir;
  const testing::OneGaussian one;
  render_and_evaluate(one.model, {one.camera}, 8, {1, 1, 1}, nullptr, no_lpips(), dir / "first");
  // The 8-bit render itself as the truth: what is scored is the file, so the scores are exact.
  const Image8 written = read_image8(rendered_view_files(dir / "first", "v").rgb);
  const Scene same_scene = one_view_scene(dir / "same_truth", one.camera, written);
  ViewImages same_truth(same_scene);
  const Evaluation same = render_and_evaluate(one.model, same_scene.cameras, 8, {1, 1, 1},
                                              &same_truth, no_lpips(), dir / "same");
  ASSERT_EQ(same.report.views.size(), 1u);
  EXPECT_EQ(same.report.views[0].name, "v");
  EXPECT_TRUE(std::isinf(same.report.views[0].psnr));
  EXPECT_NEAR(same.report.views[0].ssim, 1.0, 1e-6);  // computed in float
  EXPECT_FALSE(same.report.views[0].lpips);
  EXPECT_EQ(same.report.lpips_status, "not computed (--lpips none)");
  EXPECT_TRUE(fs::exists(dir / "same" / "metrics.json"));
  EXPECT_TRUE(fs::exists(dir / "same" / "metrics.csv"));

  const Scene black_scene = one_view_scene(dir / "black_truth", one.camera, Image8(64, 48, 3));
  ViewImages black_truth(black_scene);
  const Evaluation black = render_and_evaluate(one.model, black_scene.cameras, 8, {1, 1, 1},
                                               &black_truth, no_lpips(), dir / "black");
  ASSERT_EQ(black.report.views.size(), 1u);
  EXPECT_LT(black.report.views[0].psnr, 5);  // a mostly white render against black
}

}  // namespace
}  // namespace iesrgs::pipeline
