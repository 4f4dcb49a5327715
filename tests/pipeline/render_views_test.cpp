#include "pipeline/render_views.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cmath>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "io/npy.hpp"
#include "support/captured_log.hpp"
#include "support/one_gaussian.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::OneGaussian;

TEST(RenderViews, ViewHasTheCamerasSizeAndExpectedDepth) {
  const OneGaussian scene;
  const RenderedView view = render_view(scene.model, scene.camera, {0, 0, 1});
  ASSERT_EQ(view.image.sizes(), (std::vector<int64_t>{3, 48, 64}));
  EXPECT_GT(view.alpha[24][32].item<float>(), 0.9f);
  EXPECT_NEAR(view.depth[24][32].item<float>(), 4.0f, 0.05f);
  EXPECT_GT(view.image[0][24][32].item<float>(), 0.9f);  // red where drawn
  // Nothing drawn in the corner: the background, depth 0 rather than 0 / 0.
  EXPECT_LT(view.alpha[0][0].item<float>(), 1e-4f);
  EXPECT_EQ(view.depth[0][0].item<float>(), 0.0f);
  EXPECT_NEAR(view.image[2][0][0].item<float>(), 1.0f, 1e-4f);
}

TEST(RenderViews, WritesEveryFileAtTheScaledSize) {
  testing::TempDir dir;
  const OneGaussian scene;
  render_views_to(dir.path(), scene.model, {scene.camera}, {1, 1, 1}, 2.0);
  const RenderedViewFiles files = rendered_view_files(dir.path(), "v");
  for (const auto& png : {files.rgb, files.depth_png, files.alpha}) {
    const ImageHeader header = read_image_header(png);
    EXPECT_EQ(header.width, 128) << png;
    EXPECT_EQ(header.height, 96) << png;
  }
  const NpyArray depth = read_npy(files.depth_npy);
  ASSERT_EQ(depth.shape, (std::vector<size_t>{96, 128}));
  EXPECT_NEAR(depth.data[48 * 128 + 64], 4.0f, 0.05f);
  EXPECT_EQ(depth.data[0], 0.0f);
}

// Depth beyond what 16 bits hold at the PNG's scale clamps there; the note says so, and the .npy
// keeps the true depth.
TEST(RenderViews, SaysWhenTheDepthPngClamps) {
  testing::TempDir dir;
  OneGaussian scene;
  scene.camera = testing::camera_at({0, -70, 0}, {0, 0, 0});
  scene.camera.name = "v";
  scene.camera.intrinsics.fx = scene.camera.intrinsics.fy = 1000;  // a telephoto: still large
  ::testing::internal::CaptureStdout();
  render_views_to(dir.path(), scene.model, {scene.camera}, {1, 1, 1}, 1.0);
  const std::string output = ::testing::internal::GetCapturedStdout();
  EXPECT_NE(output.find("pixels lie farther than 65.535 scene units"), std::string::npos) << output;
  const NpyArray depth = read_npy(rendered_view_files(dir.path(), "v").depth_npy);
  EXPECT_NEAR(depth.data[24 * 64 + 32], 70.0f, 0.5f);

  ::testing::internal::CaptureStdout();
  render_views_to(dir.path(), OneGaussian().model, {OneGaussian().camera}, {1, 1, 1}, 1.0);
  EXPECT_EQ(::testing::internal::GetCapturedStdout().find("note:"), std::string::npos);
}

// Views that show nothing but the background are written, and said to be blank.
TEST(RenderViews, SaysWhenEveryViewIsBlank) {
  testing::TempDir dir;
  const OneGaussian scene;
  Camera away = testing::camera_at({0, -4, 0}, {0, -8, 0});  // the Gaussian behind it
  away.name = "away";
  testing::CapturedLog log;
  render_views_to(dir.path(), scene.model, {away}, {1, 1, 1}, 1.0);
  EXPECT_EQ(log.count("every view rendered blank"), 1u) << log.text();
  EXPECT_TRUE(std::filesystem::exists(rendered_view_files(dir.path(), "away").rgb));
  render_views_to(dir.path(), scene.model, {away, scene.camera}, {1, 1, 1}, 1.0);
  EXPECT_EQ(log.count("every view rendered blank"), 1u) << log.text();
}

// A recorded render into a folder replaces the earlier one's: its views this one does not make go
// (a run's test views after another --test-every, say), and its scores with them.
TEST(RenderViews, ARecordedRenderReplacesTheEarlierOne) {
  testing::TempDir dir;
  const OneGaussian scene;
  Camera other = scene.camera;
  other.name = "w";
  render_views_recorded(dir.path(), scene.model, {scene.camera, other}, {1, 1, 1}, 1.0,
                        {{"split", "test"}});
  write_file_atomically(dir / "metrics.json", "{}");
  EXPECT_TRUE(std::filesystem::exists(rendered_view_files(dir.path(), "w").rgb));
  render_views_recorded(dir.path(), scene.model, {scene.camera}, {0, 0, 0}, 1.0,
                        {{"split", "test"}});
  const RenderedViewFiles gone = rendered_view_files(dir.path(), "w");
  for (const auto& file : {gone.rgb, gone.depth_npy, gone.depth_png, gone.alpha})
    EXPECT_FALSE(std::filesystem::exists(file)) << file;
  EXPECT_FALSE(std::filesystem::exists(dir / "metrics.json"));
  EXPECT_TRUE(std::filesystem::exists(rendered_view_files(dir.path(), "v").rgb));
  const auto record = nlohmann::json::parse(read_file(dir / "render.json"));
  EXPECT_EQ(record["names"], nlohmann::json::array({"v"}));
  EXPECT_EQ(record["background"], nlohmann::json::array({0, 0, 0}));
  EXPECT_EQ(record["depth_png_scale"], kDepthPngScale);
  EXPECT_EQ(record["split"], "test");
  EXPECT_EQ(record["finished"], true);
}

}  // namespace
}  // namespace iesrgs::pipeline
