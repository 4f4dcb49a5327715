#include "pipeline/render_views.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cmath>

#include "io/image.hpp"
#include "io/npy.hpp"
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

}  // namespace
}  // namespace iesrgs::pipeline
