#include "pipeline/external_stage.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "support/temp_dir.hpp"
#include "synth/dataset_writer.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::TempDir;

// Rewrites are told by the file's time: an old one set beforehand, so that a rewrite within the
// file system's clock tick still shows.
// Whole seconds, which every file system stores as they are.
const auto kOld = std::chrono::floor<std::chrono::seconds>(
    std::filesystem::file_time_type::clock::now() - std::chrono::hours(48));

void mark_old(const std::filesystem::path& file) {
  std::filesystem::last_write_time(file, kOld);
}

bool rewritten(const std::filesystem::path& file) {
  return std::filesystem::last_write_time(file) != kOld;
}

TEST(ExternalStage, SuperResolvesEveryTrainingViewOnceAndRecomputesOnChange) {
  TempDir dir;
  synth::SynthOptions synth;
  synth.size = 32;
  synth.train_views = 3;
  synth.test_views = 1;
  synth::write_synth_dataset(dir / "scene", synth);
  SceneOptions lr;
  lr.downscale = 2;
  const Scene scene = load_scene(dir / "scene", lr);
  ViewImages images(scene);
  ExternalOptions options;
  options.sr_model = "bicubic";
  options.scale = 2;

  const std::vector<ExternalView> views = run_external_stage(scene, images, options, dir / "ext");
  ASSERT_EQ(views.size(), 3u);
  const ImageHeader header = read_image_header(views[0].image);
  EXPECT_EQ(header.width, 32);
  EXPECT_TRUE(views[0].depth.empty());  // no depth model
  mark_old(views[0].image);
  mark_old(views[1].image);

  run_external_stage(scene, images, options, dir / "ext");  // cached: nothing rewritten
  EXPECT_FALSE(rewritten(views[0].image));
  // Depth weights are unused without a depth model: naming a file changes nothing.
  ExternalOptions unused_weights = options;
  unused_weights.depth_weights = dir / "scene" / "transforms_train.json";
  run_external_stage(scene, images, unused_weights, dir / "ext");
  EXPECT_FALSE(rewritten(views[0].image));

  // The same bytes written again (a copied dataset) keep the cache; an edited image does not.
  const Camera& first = *scene.split(Split::Train)[0];
  write_file_atomically(first.image_path, read_file(first.image_path));
  run_external_stage(scene, images, options, dir / "ext");
  EXPECT_FALSE(rewritten(views[0].image));
  Image8 edited = read_image8(first.image_path);
  edited.data[0] ^= 0xff;
  write_png(first.image_path, edited);
  ViewImages reread(scene);
  run_external_stage(scene, reread, options, dir / "ext");
  EXPECT_TRUE(rewritten(views[0].image));
  EXPECT_FALSE(rewritten(views[1].image));

  // A damaged cached file, or one replaced by an image of another size, is computed again.
  const std::string good = read_file(views[1].image);
  write_file_atomically(views[1].image, good.substr(0, good.size() / 2));
  write_png(views[2].image, Image8(5, 5, 3));
  run_external_stage(scene, images, options, dir / "ext");
  EXPECT_EQ(read_file(views[1].image), good);
  EXPECT_EQ(read_image_header(views[2].image).width, 32);

  // A new lens for the second view undistorts its image differently: computed again.
  Scene lensed = scene;
  for (Camera& camera : lensed.cameras)
    if (camera.split == Split::Train && camera.name == scene.split(Split::Train)[1]->name)
      camera.distortion.k1 = 0.05;
  ViewImageOptions lens_options;
  lens_options.undistort_cache_dir = dir / "undistorted";
  ViewImages lensed_images(lensed, lens_options);
  mark_old(views[1].image);
  run_external_stage(lensed, lensed_images, options, dir / "ext");
  EXPECT_TRUE(rewritten(views[1].image));
  EXPECT_NE(read_file(views[1].image), good);

  options.scale = 4;  // a different stage: every view again
  run_external_stage(scene, images, options, dir / "ext");
  EXPECT_EQ(read_image_header(views[0].image).width, 64);
}

}  // namespace
}  // namespace iesrgs::pipeline
