#include "train/session.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "support/expect_error.hpp"
#include "support/looking_cameras.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::train {
namespace {

using testing::camera_at;

// A capture of cameras at the given places, all looking at `target`.
Scene capture(const std::vector<Vec3>& eyes, const Vec3& target) {
  Scene scene;
  for (const Vec3& eye : eyes) scene.cameras.push_back(camera_at(eye, target));
  return scene;
}

// A training stopped before its first checkpoint left its log and config, and no model.
TEST(TrainedModelFile, AFolderWithoutAModelSaysWhy) {
  testing::TempDir dir;
  testing::write_text(dir / "run" / "config.json", "{}");
  testing::write_text(dir / "run" / "train_log.csv", "iteration\n");
  EXPECT_TRUE(is_training_folder(dir / "run"));
  EXPECT_TRUE(testing::contains(testing::error_message([&] { trained_model_file(dir / "run"); }),
                                "its training stopped before its first checkpoint"));
  testing::write_text(dir / "run" / "checkpoint.pt", "");
  EXPECT_TRUE(testing::contains(testing::error_message([&] { trained_model_file(dir / "run"); }),
                                "its training has not finished"));
  EXPECT_FALSE(is_training_folder(dir.path()));
}

TEST(RandomBox, ConfiguredExtentIsACubeAroundTheOrigin) {
  TrainConfig config;
  config.random_extent = 3;
  const RandomBox box = random_box(capture({{5, 0, 1}, {0, 5, 1}, {-5, 0, 1}}, {1, 1, 0}), config);
  EXPECT_EQ(box.half_extent, 3);
  EXPECT_EQ(box.center.norm(), 0);
}

TEST(RandomBox, NerfSyntheticScenesTakeThreeDgsCube) {
  Scene scene = capture({{4, 0, 1}, {0, 4, 1}, {-4, 0, 1}}, {0, 0, 0});
  scene.synthetic = true;
  const RandomBox box = random_box(scene, TrainConfig{});
  EXPECT_NEAR(box.half_extent, 1.3, 1e-12);
  EXPECT_EQ(box.center.norm(), 0);
}

TEST(RandomBox, CapturesTakeTheCubeAroundWhatTheCamerasLookAtReachingTheNearest) {
  const Vec3 target{10, -2, 1};
  const RandomBox box = random_box(
      capture({target + Vec3{6, 0, 0}, target + Vec3{0, 4, 3}, target + Vec3{-8, 0, 0}}, target),
      TrainConfig{});
  EXPECT_NEAR((box.center - target).norm(), 0, 1e-9);
  EXPECT_NEAR(box.half_extent, 5, 1e-9);
}

TEST(RandomBox, ParallelCamerasTakeTheNormalizationSphere) {
  // Both look along +y, so their axes never meet.
  Scene parallel;
  parallel.cameras = {camera_at({0, 0, 0}, {0, 5, 0}), camera_at({2, 0, 0}, {2, 5, 0})};
  const RandomBox box = random_box(parallel, TrainConfig{});
  EXPECT_NEAR((box.center - Vec3{1, 0, 0}).norm(), 0, 1e-9);
  EXPECT_NEAR(box.half_extent, 1.1, 1e-9);  // 3DGS: 1.1 x the farthest camera from the center
}

}  // namespace
}  // namespace iesrgs::train
