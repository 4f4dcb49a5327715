#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

#include "io/atomic_file.hpp"
#include "io/camera.hpp"
#include "io/colmap.hpp"
#include "io/image.hpp"
#include "io/npy.hpp"
#include "io/scene.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"
#include "synth/dataset_writer.hpp"
#include "synth/renderer.hpp"

namespace iesrgs::synth {
namespace {

using testing::error_message;
using testing::TempDir;

constexpr int kSize = 32;

SynthOptions tiny(uint64_t seed = 7) {
  SynthOptions options;
  options.size = kSize;
  options.train_views = 3;
  options.test_views = 2;
  options.seed = seed;
  return options;
}

nlohmann::json read_json(const std::filesystem::path& path) {
  return nlohmann::json::parse(read_file(path));
}

// Every file a tiny scene consists of, relative to its directory.
std::vector<std::string> scene_files() {
  std::vector<std::string> files{"transforms_train.json", "transforms_test.json"};
  for (const auto& [split, count] : {std::pair{"train", 3}, std::pair{"test", 2}}) {
    for (int i = 0; i < count; ++i) {
      const std::string stem = std::string(split) + "/r_" + std::to_string(i);
      files.push_back(stem + ".png");
      files.push_back(stem + "_depth.npy");
    }
  }
  return files;
}

TEST(SynthDataset, WritesTheNerfSyntheticLayout) {
  TempDir dir;
  write_synth_dataset(dir.path(), tiny());
  for (const std::string& file : scene_files())
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / file)) << file;

  for (const auto& [split, count] : {std::pair{"train", 3}, std::pair{"test", 2}}) {
    const nlohmann::json transforms =
        read_json(dir / (std::string("transforms_") + split + ".json"));
    EXPECT_NEAR(transforms.at("camera_angle_x").get<double>(), 0.6911112070083618, 1e-15);
    const auto& frames = transforms.at("frames");
    ASSERT_EQ(frames.size(), size_t(count));
    for (int i = 0; i < count; ++i) {
      EXPECT_EQ(frames[i].at("file_path"), std::string("./") + split + "/r_" + std::to_string(i));
      const auto m = frames[i].at("transform_matrix").get<std::vector<std::vector<double>>>();
      ASSERT_EQ(m.size(), 4u);
      for (const auto& row : m) ASSERT_EQ(row.size(), 4u);
      EXPECT_EQ(m[3], (std::vector<double>{0, 0, 0, 1}));
      EXPECT_NEAR(std::sqrt(m[0][3] * m[0][3] + m[1][3] * m[1][3] + m[2][3] * m[2][3]),
                  kOrbitRadius, 1e-9);
      EXPECT_GT(m[2][3], 0);  // above the horizon
    }
  }
  const Image8 image = read_image8(dir / "train/r_0.png");
  EXPECT_EQ(image.width, kSize);
  EXPECT_EQ(image.height, kSize);
  EXPECT_EQ(image.channels, 4);
}

TEST(SynthDataset, BackgroundIsTransparentAndTheObjectOpaque) {
  TempDir dir;
  write_synth_dataset(dir.path(), tiny());
  for (const std::string stem : {"train/r_0", "train/r_2", "test/r_1"}) {
    const Image8 image = read_image8(dir / (stem + ".png"));
    for (int x : {0, kSize - 1})
      for (int y : {0, kSize - 1}) EXPECT_EQ(image.at(x, y, 3), 0) << stem;
    // The tower in the middle of the scene stands around the origin, where every camera looks.
    EXPECT_EQ(image.at(kSize / 2, kSize / 2, 3), 255) << stem;
  }
}

TEST(SynthDataset, DepthRoundTripsThroughNpy) {
  TempDir dir;
  write_synth_dataset(dir.path(), tiny());
  const NpyArray depth = read_npy(dir / "train/r_1_depth.npy");
  EXPECT_EQ(depth.shape, (std::vector<size_t>{kSize, kSize}));
  RenderSettings settings;
  settings.width = settings.height = kSize;
  settings.grid = int(std::lround(std::sqrt(default_samples(kSize))));
  const RenderedView view = render_view(make_synth_scene(7), train_orbit(3, 7)[1], settings);
  EXPECT_EQ(depth.data, view.depth);
  const float center = depth.data[kSize / 2 * kSize + kSize / 2];
  EXPECT_GT(center, kOrbitRadius - 1.3);
  EXPECT_LT(center, kOrbitRadius + 1.3);
  EXPECT_EQ(depth.data[0], 0.f);
}

TEST(SynthDataset, SameSeedSameBytesOtherSeedOtherScene) {
  TempDir a, b, c;
  write_synth_dataset(a.path(), tiny(7));
  write_synth_dataset(b.path(), tiny(7));
  write_synth_dataset(c.path(), tiny(8));
  for (const std::string& file : scene_files())
    EXPECT_EQ(read_file(a / file), read_file(b / file)) << file;
  for (const char* file : {"train/r_0.png", "train/r_0_depth.npy", "test/r_1.png"})
    EXPECT_NE(read_file(a / file), read_file(c / file)) << file;
}

TEST(SynthDataset, CamerasLookAtTheOriginThroughTheImageCenter) {
  TempDir dir;
  write_synth_dataset(dir.path(), tiny());
  const auto frames = read_json(dir / "transforms_train.json").at("frames");
  const double focal = 0.5 * kSize / std::tan(0.5 * kCameraAngleX);
  for (const auto& frame : frames) {
    const auto m = frame.at("transform_matrix").get<std::vector<std::vector<double>>>();
    double c2w[4][4];
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) c2w[r][c] = m[r][c];
    Mat3 rotation;
    Vec3 translation;
    opengl_c2w_to_opencv_w2c(c2w, rotation, translation);
    const Vec3 origin = rotation * Vec3{0, 0, 0} + translation;  // in OpenCV camera space
    ASSERT_GT(origin.z, 0);                                      // in front of the camera
    EXPECT_NEAR(focal * origin.x / origin.z + 0.5 * kSize, 0.5 * kSize, 1e-9);
    EXPECT_NEAR(focal * origin.y / origin.z + 0.5 * kSize, 0.5 * kSize, 1e-9);
    EXPECT_NEAR(origin.z, kOrbitRadius, 1e-9);
  }
}

TEST(SynthDataset, ReportsProgressPerView) {
  TempDir dir;
  std::vector<std::pair<int, int>> calls;
  write_synth_dataset(dir.path(), tiny(),
                      [&](int done, int total) { calls.emplace_back(done, total); });
  ASSERT_EQ(calls.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(calls[i], std::make_pair(i + 1, 5));
}

// Stopped partway (here by an error from the progress callback, as Ctrl-C stops the command), a
// scene written over an earlier one leaves no scene: not the earlier cameras over new images.
TEST(SynthDataset, AStoppedSceneIsNoScene) {
  TempDir dir;
  for (const SynthFormat format : {SynthFormat::Blender, SynthFormat::Colmap}) {
    SynthOptions options = tiny();
    options.format = format;
    write_synth_dataset(dir.path(), options);
    ASSERT_TRUE(is_scene(dir.path()));
    options.seed = 8;
    const std::string message = error_message([&] {
      write_synth_dataset(dir.path(), options, [](int done, int) {
        if (done == 4) fail("stopped");
      });
    });
    EXPECT_EQ(message, "stopped");
    EXPECT_FALSE(is_scene(dir.path()));
    write_synth_dataset(dir.path(), options);  // and written again, whole
    EXPECT_TRUE(is_scene(dir.path()));
  }
}

// A record that cannot be written (here a folder stands in its place) leaves no scene: one without
// its record would be refused by the next synth as another's.
TEST(SynthDataset, ASceneWhoseRecordFailsIsNoScene) {
  for (const SynthFormat format : {SynthFormat::Blender, SynthFormat::Colmap}) {
    TempDir dir;
    std::filesystem::create_directories(dir / "synth.json" / "in-the-way");
    SynthOptions options = tiny();
    options.format = format;
    EXPECT_FALSE(error_message([&] { write_synth_dataset(dir.path(), options); }).empty());
    EXPECT_FALSE(is_scene(dir.path()));
    EXPECT_FALSE(std::filesystem::exists(dir / "sparse"));
    std::filesystem::remove_all(dir / "synth.json");
    write_synth_dataset(dir.path(), options);
    EXPECT_TRUE(is_scene(dir.path()));
  }
}

// A capture's COLMAP model or a dataset's transforms are not synth's to replace, nor synth's own
// once changed: only the files synth.json records, as it records them.
TEST(SynthDataset, AFolderHoldingAnotherSceneIsRefusedUntouched) {
  TempDir dir;
  SynthOptions options = tiny();
  options.format = SynthFormat::Colmap;
  write_synth_dataset(dir.path(), options);
  EXPECT_EQ(read_json(dir / "synth.json")["format"], "colmap");
  const std::string model = read_file(dir / "sparse" / "0" / "images.bin");
  const auto refusal = [&](const std::string& file) {
    return dir.path().string() + ": holds a scene synth did not write (" + file +
           " is not as synth.json records it); write the synthetic scene into another folder";
  };
  // A text model beside synth's binary one, which a reader would take were the binary removed.
  testing::write_text(dir / "sparse" / "0" / "cameras.txt", "# by hand\n");
  EXPECT_EQ(error_message([&] { write_synth_dataset(dir.path(), options); }),
            refusal("sparse/0/cameras.txt"));
  std::filesystem::remove(dir / "sparse" / "0" / "cameras.txt");
  std::filesystem::remove(dir / "synth.json");  // now a capture of someone else's
  for (const SynthFormat format : {SynthFormat::Blender, SynthFormat::Colmap}) {
    options.format = format;
    EXPECT_EQ(error_message([&] { write_synth_dataset(dir.path(), options); }),
              refusal("sparse/0/cameras.bin"));
  }
  EXPECT_EQ(read_file(dir / "sparse" / "0" / "images.bin"), model);

  // A nerfstudio capture, whose transforms.json synth's own files would shadow.
  TempDir nerfstudio;
  testing::write_text(nerfstudio / "transforms.json", R"({"frames": []})");
  EXPECT_EQ(error_message([&] { write_synth_dataset(nerfstudio.path(), tiny()); }),
            nerfstudio.path().string() +
                ": holds a scene synth did not write (transforms.json is not as synth.json "
                "records it); write the synthetic scene into another folder");
  EXPECT_FALSE(std::filesystem::exists(nerfstudio / "transforms_train.json"));
}

TEST(SynthDataset, RejectsBadOptions) {
  TempDir dir;
  SynthOptions options = tiny();
  options.size = 0;
  EXPECT_EQ(error_message([&] { write_synth_dataset(dir.path(), options); }),
            "synthetic scene: size must be 8 to 8192 pixels, got 0");
  options = tiny();
  options.samples = 5;
  EXPECT_EQ(error_message([&] { write_synth_dataset(dir.path(), options); }),
            "synthetic scene: samples per pixel must be a square number from 1 to 1024, got 5");
  options = tiny();
  options.train_views = 0;
  EXPECT_NE(error_message([&] { write_synth_dataset(dir.path(), options); }).find("training views"),
            std::string::npos);
  options = tiny();
  options.test_views = -1;
  EXPECT_NE(error_message([&] { write_synth_dataset(dir.path(), options); }).find("test views"),
            std::string::npos);
  options = tiny();
  options.format = SynthFormat::Colmap;
  options.train_views = 1;
  options.test_views = 0;
  EXPECT_EQ(error_message([&] { write_synth_dataset(dir.path(), options); }),
            "synthetic scene: a COLMAP capture holds out its first image for test, so it needs "
            "at least 2 views and test views together, got 1");
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(SynthDataset, UnwritableDirectoryIsAnErrorNamingIt) {
  TempDir dir;
  testing::write_text(dir / "file", "not a directory");
  const std::string message = error_message([&] { write_synth_dataset(dir / "file", tiny()); });
  EXPECT_NE(message.find((dir / "file").string()), std::string::npos) << message;
}

}  // namespace
}  // namespace iesrgs::synth

namespace iesrgs::synth {
namespace {

TEST(SynthColmap, LoadsAsAColmapSceneWhosePointsProjectOntoTheirObservations) {
  TempDir dir;
  SynthOptions options = tiny();
  options.format = SynthFormat::Colmap;
  options.train_views = 7;
  options.test_views = 2;
  write_synth_dataset(dir.path(), options);
  const Scene scene = load_scene(dir.path());
  EXPECT_EQ(scene.format, "colmap");
  ASSERT_EQ(scene.cameras.size(), 9u);
  EXPECT_EQ(scene.split(Split::Test).size(), 2u);  // r_0000 and r_0008
  ASSERT_GT(scene.points.positions.size(), 50u);

  const ColmapModel model = read_colmap_model(dir / "sparse" / "0");
  for (const ColmapPoint& point : model.points) {
    ASSERT_EQ(point.track.size(), 1u);
    const ColmapImage& image = model.images.at(point.track[0].image_id);
    const Camera& camera = scene.cameras[image.id - 1];  // names sort in writing order
    ASSERT_EQ(camera.name + ".png", image.name);
    const Vec3 p = camera.rotation * Vec3{point.x, point.y, point.z} + camera.translation;
    const ColmapObservation& seen = image.observations[point.track[0].point2d_index];
    const Intrinsics& k = camera.intrinsics;
    EXPECT_NEAR(k.fx * p.x / p.z + k.cx, seen.x, 1e-3);
    EXPECT_NEAR(k.fy * p.y / p.z + k.cy, seen.y, 1e-3);
    // The point's colour is the photo's pixel there (fully covered pixels only).
    const Image8 photo = read_image8(camera.image_path);
    const int x = int(seen.x), y = int(seen.y);
    EXPECT_NEAR(photo.at(x, y, 0), point.r, 1);
    EXPECT_NEAR(photo.at(x, y, 2), point.b, 1);
  }
}

}  // namespace
}  // namespace iesrgs::synth
