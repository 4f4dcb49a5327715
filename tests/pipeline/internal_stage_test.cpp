#include "pipeline/internal_stage.hpp"

#include <gtest/gtest.h>

#include "io/image.hpp"
#include "pipeline/render_views.hpp"
#include "pipeline/stage_record.hpp"
#include "support/temp_dir.hpp"
#include "synth/dataset_writer.hpp"
#include "train/session.hpp"

namespace iesrgs::pipeline {
namespace {

namespace fs = std::filesystem;

// A 16x16 scene of 4 training views and a 3-iteration schedule from random points.
struct TinyLrScene {
  testing::TempDir dir;
  Scene scene;
  train::TrainConfig config = train::make_preset("fast", 3);

  TinyLrScene() {
    synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 16, 4, 1});
    scene = load_scene(dir / "scene");
    config.checkpoint_every = 0;
    config.test_every = 0;
    config.init = "random";
    config.random_points = 200;
  }
};

TEST(InternalStage, RendersEveryTrainingViewAtTheScaleAndIsReusedWhileCurrent) {
  TinyLrScene lr;
  ViewImages images(lr.scene);
  const std::string digest = split_digest(images, Split::Train);
  const fs::path out = lr.dir / "internal";
  EXPECT_FALSE(internal_stage_current(lr.scene, digest, lr.config, 2, out));

  const InternalStage first = run_internal_stage(lr.scene, digest, images, lr.config, 2, out);
  EXPECT_FALSE(first.training.cached);
  EXPECT_EQ(first.sr_dir, out / "sr");
  for (const Camera* camera : lr.scene.split(Split::Train)) {
    const ImageHeader rgb = read_image_header(rendered_view_files(first.sr_dir, camera->name).rgb);
    EXPECT_EQ(rgb.width, 32) << camera->name;  // I_image at 2x the LR view, same field of view
    EXPECT_EQ(rgb.height, 32) << camera->name;
    EXPECT_TRUE(fs::exists(rendered_view_files(first.sr_dir, camera->name).depth_npy));
  }
  EXPECT_TRUE(internal_stage_current(lr.scene, digest, lr.config, 2, out));
  EXPECT_FALSE(internal_stage_current(lr.scene, digest, lr.config, 4, out));  // another scale
  train::TrainConfig longer = lr.config;
  longer.iterations = 4;
  EXPECT_FALSE(internal_stage_current(lr.scene, digest, longer, 2, out));

  // A render deleted since: the cached model renders every view again, without training.
  const fs::path one = rendered_view_files(first.sr_dir, lr.scene.split(Split::Train)[0]->name).rgb;
  fs::remove(one);
  EXPECT_FALSE(internal_stage_current(lr.scene, digest, lr.config, 2, out));
  const InternalStage again = run_internal_stage(lr.scene, digest, images, lr.config, 2, out);
  EXPECT_TRUE(again.training.cached);
  EXPECT_TRUE(fs::exists(one));
  EXPECT_TRUE(internal_stage_current(lr.scene, digest, lr.config, 2, out));
}

}  // namespace
}  // namespace iesrgs::pipeline
