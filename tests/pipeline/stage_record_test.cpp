#include "pipeline/stage_record.hpp"

#include <gtest/gtest.h>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "io/npy.hpp"
#include "support/temp_dir.hpp"
#include "synth/dataset_writer.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::TempDir;

// Digests are taken once per ViewImages (one run), so each check reads the files afresh.
std::string train_digest(const Scene& scene) {
  return split_digest(ViewImages(scene), Split::Train);
}

TEST(StageRecord, FinishedWithTheSameParametersAndItsTime) {
  TempDir dir;
  EXPECT_FALSE(stage_finished(dir.path(), {{"a", 1}}));
  record_stage(dir.path(), {{"a", 1}}, false, 3);
  EXPECT_TRUE(stage_recorded(dir.path(), {{"a", 1}}));
  EXPECT_FALSE(stage_finished(dir.path(), {{"a", 1}}));
  record_stage(dir.path(), {{"a", 1}}, true, 5);
  EXPECT_TRUE(stage_finished(dir.path(), {{"a", 1}}));
  EXPECT_FALSE(stage_finished(dir.path(), {{"a", 2}}));
  EXPECT_EQ(stage_seconds(dir.path()), 5);
}

// Damaged from outside: the record counts as none and the stage is made again, never a failure.
TEST(StageRecord, MistypedOrUnreadableRecordCountsAsNone) {
  TempDir dir;
  for (const char* damaged :
       {R"({"params": {}, "finished": "yes", "seconds": 5})",
        R"({"params": {}, "finished": true, "seconds": "many"})", R"({"params": {}, "fin)"}) {
    write_file_atomically(dir / "stage.json", damaged);
    EXPECT_FALSE(stage_finished(dir.path(), nlohmann::json::object())) << damaged;
    EXPECT_EQ(stage_seconds(dir.path()), 0) << damaged;
  }
}

TEST(StageRecord, CachedViewIsIntactOnlyWhenItDecodesAtItsSize) {
  TempDir dir;
  const auto image = dir / "v.png", depth = dir / "v.npy";
  write_png(image, Image8(6, 4, 3));
  write_npy(depth, std::vector<float>(24, 1.f), {4, 6});
  EXPECT_TRUE(cached_view_intact(image, depth, 6, 4));
  EXPECT_TRUE(cached_view_intact(image, {}, 6, 4));  // no depth map to check
  EXPECT_FALSE(cached_view_intact(image, depth, 12, 8));
  EXPECT_FALSE(cached_view_intact(dir / "missing.png", {}, 6, 4));
  write_npy(depth, std::vector<float>(24, 1.f), {6, 4});
  EXPECT_FALSE(cached_view_intact(image, depth, 6, 4));
  const std::string bytes = read_file(image);
  write_file_atomically(image, bytes.substr(0, bytes.size() - 8));
  EXPECT_FALSE(cached_view_intact(image, {}, 6, 4));
}

TEST(StageRecord, SplitDigestFollowsCamerasImageContentAndBackground) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 16, 2, 1});
  Scene scene = load_scene(dir / "scene", {});
  const std::string digest = train_digest(scene);
  EXPECT_NE(digest, split_digest(ViewImages(scene), Split::Test));

  const auto image = scene.split(Split::Train)[1]->image_path;
  write_file_atomically(image, read_file(image));  // same bytes, new file
  EXPECT_EQ(train_digest(scene), digest);

  std::filesystem::rename(dir / "scene", dir / "copied");  // a moved dataset keeps its caches
  EXPECT_EQ(train_digest(load_scene(dir / "copied", {})), digest);
  std::filesystem::rename(dir / "copied", dir / "scene");

  Scene moved = scene;
  for (Camera& camera : moved.cameras)
    if (camera.split == Split::Train) camera.translation.z += 1e-9;
  EXPECT_NE(train_digest(moved), digest);

  Scene black = scene;
  black.background = {0, 0, 0};
  EXPECT_NE(train_digest(black), digest);

  Image8 edited = read_image8(image);
  edited.data[0] ^= 1;
  write_png(image, edited);
  EXPECT_NE(train_digest(scene), digest);
}

TEST(StageRecord, SplitDigestReadsThePreDownscaledCopyWhenThereIsOne) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 16, 2, 1});
  const Scene half = load_scene(dir / "scene", SceneOptions{2});
  const std::string digest = train_digest(half);
  const auto image = half.split(Split::Train)[0]->image_path;
  const auto copy = image.parent_path().parent_path() /
                    (image.parent_path().filename().string() + "_2") / image.filename();
  std::filesystem::create_directories(copy.parent_path());
  Image8 other = read_image8(image);  // not a half-size image: only its bytes count here
  other.data[0] ^= 1;
  write_png(copy, other);
  EXPECT_NE(train_digest(half), digest);
}

TEST(StageRecord, PointsDigestFollowsPositionsAndColors) {
  PointCloud points{{{0, 0, 0}, {1, 2, 3}}, {{{1, 2, 3}}, {{4, 5, 6}}}};
  const std::string digest = points_digest(points);
  EXPECT_NE(digest, points_digest({}));
  points.colors[1][0] = 7;
  EXPECT_NE(points_digest(points), digest);
}

}  // namespace
}  // namespace iesrgs::pipeline
