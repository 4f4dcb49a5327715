#include "pipeline/stage_record.hpp"

#include <gtest/gtest.h>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "support/temp_dir.hpp"
#include "synth/dataset_writer.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::TempDir;

TEST(StageRecord, SplitDigestFollowsCamerasAndImageContent) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 16, 2, 1});
  Scene scene = load_scene(dir / "scene", {});
  const std::string digest = split_digest(scene, Split::Train);
  EXPECT_NE(digest, split_digest(scene, Split::Test));

  const auto image = scene.split(Split::Train)[1]->image_path;
  write_file_atomically(image, read_file(image));  // same bytes, new file
  EXPECT_EQ(split_digest(scene, Split::Train), digest);

  Scene moved = scene;
  for (Camera& camera : moved.cameras)
    if (camera.split == Split::Train) camera.translation.z += 1e-9;
  EXPECT_NE(split_digest(moved, Split::Train), digest);

  Image8 edited = read_image8(image);
  edited.data[0] ^= 1;
  write_png(image, edited);
  EXPECT_NE(split_digest(scene, Split::Train), digest);
}

}  // namespace
}  // namespace iesrgs::pipeline
