#include <gtest/gtest.h>

#include <fstream>

#include "io/atomic_file.hpp"
#include "io/view_images.hpp"
#include "support/captured_log.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::error_message;
using testing::TempDir;

Image8 solid(int w, int h, std::vector<uint8_t> color) {
  Image8 image(w, h, static_cast<int>(color.size()));
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = color[i % color.size()];
  return image;
}

Camera camera_for(const std::filesystem::path& path, int w, int h) {
  Camera camera;
  camera.name = path.stem().string();
  camera.image_path = path;
  camera.stored = {w, h, double(w), double(w), w / 2.0, h / 2.0};
  camera.intrinsics = camera.pinhole = camera.stored;  // as load_scene sets them
  return camera;
}

struct SceneFixture {
  TempDir dir;
  Scene scene;
  ViewImageOptions options;

  SceneFixture() {
    scene.root = dir.path();
    options.undistort_cache_dir = dir / "cache";
  }
  const Camera& add(const std::string& name, const Image8& image) {
    write_png(dir / "images" / name, image);
    scene.cameras.push_back(camera_for(dir / "images" / name, image.width, image.height));
    return scene.cameras.back();
  }
};

TEST(ViewImages, CompositesRgbaOverTheSceneBackground) {
  SceneFixture f;
  f.scene.background = {0, 0, 1};
  const Camera camera = f.add("a.png", solid(6, 4, {255, 0, 0, 0}));
  ViewImages images(f.scene, f.options);
  const auto rgb = images.rgb(camera);
  ASSERT_EQ(rgb->channels, 3);
  EXPECT_EQ(rgb->width, 6);
  EXPECT_FLOAT_EQ(rgb->at(3, 2, 0), 0.f);
  EXPECT_FLOAT_EQ(rgb->at(3, 2, 2), 1.f);
}

TEST(ViewImages, PrefersThePreDownscaledFolder) {
  SceneFixture f;
  Camera camera = f.add("a.png", solid(8, 8, {255, 0, 0}));
  write_png(f.dir / "images_2" / "a.png", solid(4, 4, {0, 255, 0}));
  f.scene.downscale = 2;
  camera.intrinsics = camera.stored.scaled(0.5);
  ViewImages images(f.scene, f.options);
  const auto rgb = images.rgb(camera);
  EXPECT_EQ(rgb->width, 4);
  EXPECT_FLOAT_EQ(rgb->at(1, 1, 1), 1.f);  // green: the downscaled copy, not the original
}

// A rig's images/cam0/a.png has its copy in images_2/cam0/a.png.
TEST(ViewImages, FindsThePreDownscaledCopyOfANestedImage) {
  SceneFixture f;
  Camera camera = f.add("cam0/a.png", solid(8, 8, {255, 0, 0}));
  write_png(f.dir / "images_2" / "cam0" / "a.png", solid(4, 4, {0, 255, 0}));
  f.scene.downscale = 2;
  camera.intrinsics = camera.stored.scaled(0.5);
  ViewImages images(f.scene, f.options);
  EXPECT_FLOAT_EQ(images.rgb(camera)->at(1, 1, 1), 1.f);
}

TEST(ViewImages, FindsThePreDownscaledCopyOfASceneGivenAsItsJsonFile) {
  SceneFixture f;
  Camera camera = f.add("a.png", solid(8, 8, {255, 0, 0}));
  write_png(f.dir / "images_2" / "a.png", solid(4, 4, {0, 255, 0}));
  write_file_atomically(f.dir / "transforms.json", "{}");
  f.scene.root = f.dir / "transforms.json";
  f.scene.downscale = 2;
  camera.intrinsics = camera.stored.scaled(0.5);
  ViewImages images(f.scene, f.options);
  EXPECT_FLOAT_EQ(images.rgb(camera)->at(1, 1, 1), 1.f);
}

TEST(ViewImages, ResizesWhenNoDownscaledCopyExists) {
  SceneFixture f;
  Camera camera = f.add("a.png", solid(8, 6, {10, 200, 30}));
  f.scene.downscale = 2;
  camera.intrinsics = camera.stored.scaled(0.5);
  ViewImages images(f.scene, f.options);
  const auto rgb = images.rgb(camera);
  EXPECT_EQ(rgb->width, 4);
  EXPECT_EQ(rgb->height, 3);
  EXPECT_NEAR(rgb->at(2, 1, 1), 200 / 255.f, 1e-6);  // a constant image stays constant
}

// A copy folder lacking some images mixes two resizes of one scene: said once, naming the first.
TEST(ViewImages, ACopyFolderLackingImagesIsSaidOnce) {
  SceneFixture f;
  Camera a = f.add("a.png", solid(8, 8, {255, 0, 0}));
  Camera b = f.add("b.png", solid(8, 8, {255, 0, 0}));
  Camera c = f.add("c.png", solid(8, 8, {255, 0, 0}));
  write_png(f.dir / "images_2" / "a.png", solid(4, 4, {0, 255, 0}));
  f.scene.downscale = 2;
  for (Camera* camera : {&a, &b, &c}) camera->intrinsics = camera->stored.scaled(0.5);
  testing::CapturedLog log;
  ViewImages images(f.scene, f.options);
  EXPECT_FLOAT_EQ(images.rgb(a)->at(1, 1, 1), 1.f);
  EXPECT_FLOAT_EQ(images.rgb(b)->at(1, 1, 0), 1.f);  // red: resized from the stored image
  images.rgb(c);
  EXPECT_EQ(log.count((f.dir / "images_2").string() +
                      ": holds no copy of b.png (the first of the scene's images it lacks); such "
                      "views are resized from the stored images instead"),
            1u)
      << log.text();
  EXPECT_EQ(log.count("holds no copy"), 1u) << log.text();
}

TEST(ViewImages, WrongImageSizeNamesTheFile) {
  SceneFixture f;
  Camera camera = f.add("a.png", solid(8, 6, {1, 2, 3}));
  camera.stored.width = 9;
  ViewImages images(f.scene, f.options);
  const std::string message = error_message([&] { images.rgb(camera); });
  EXPECT_NE(message.find("a.png: image is 8x6, expected 9x6"), std::string::npos) << message;
}

// A NeRF-Synthetic split takes its size from its first image: when that one is the odd one out,
// the error must point at it, not only at the image that failed.
TEST(ViewImages, WrongSizeInNerfSyntheticNamesTheImageTheSizeCameFrom) {
  SceneFixture f;
  f.scene.format = "blender";
  f.add("r_0.png", solid(8, 6, {1, 2, 3}));
  Camera second = f.add("r_1.png", solid(9, 6, {1, 2, 3}));
  second.stored = f.scene.cameras.front().stored;
  ViewImages images(f.scene, f.options);
  const std::string message = error_message([&] { images.rgb(second); });
  EXPECT_NE(message.find("r_1.png: image is 9x6, expected 8x6 (the size of "), std::string::npos)
      << message;
  EXPECT_NE(message.find("r_0.png, the first image of its split"), std::string::npos) << message;
}

TEST(ViewImages, KeepsAtMostTheCacheBudget) {
  SceneFixture f;
  const Camera a = f.add("a.png", solid(4, 4, {1, 2, 3}));
  const Camera b = f.add("b.png", solid(4, 4, {4, 5, 6}));
  f.options.cache_bytes = 4 * 4 * 3 * sizeof(float);  // room for exactly one image
  ViewImages images(f.scene, f.options);
  const auto first = images.rgb(a);
  EXPECT_EQ(images.rgb(a), first);  // served from memory
  images.rgb(b);                    // evicts a
  EXPECT_NE(images.rgb(a), first);
}

TEST(ViewImages, UndistortsOnceIntoTheCache) {
  SceneFixture f;
  Camera camera = f.add("a.png", solid(16, 12, {9, 99, 199}));
  camera.distortion = {0.05, 0, 0, 0};
  ViewImages images(f.scene, f.options);
  const Image8 first = images.read8(camera);
  ASSERT_TRUE(std::filesystem::is_directory(f.options.undistort_cache_dir));
  int cached = 0;
  for (const auto& entry : std::filesystem::directory_iterator(f.options.undistort_cache_dir))
    cached += entry.path().extension() == ".png";
  EXPECT_EQ(cached, 1);
  EXPECT_EQ(images.read8(camera).data, first.data);
}

// A cache that cannot be written (here a file holds its folder's name) leaves the images
// undistorted all the same, and says so once, not once per image.
TEST(ViewImages, ACacheThatCannotBeWrittenIsSaidOnce) {
  SceneFixture f;
  std::ofstream(f.dir / "taken") << "x";
  f.options.undistort_cache_dir = f.dir / "taken" / "undistorted";
  Camera a = f.add("a.png", solid(16, 12, {9, 99, 199}));
  Camera b = f.add("b.png", solid(16, 12, {9, 99, 199}));
  a.distortion = b.distortion = {0.05, 0, 0, 0};
  testing::CapturedLog log;
  ViewImages images(f.scene, f.options);
  EXPECT_EQ(images.read8(a).data, images.read8(b).data);
  EXPECT_EQ(log.count("cannot cache undistorted images"), 1u) << log.text();
}

// The cache entry is named by the source's content: a copy with a new time reuses it, an edited
// image (read by the next run) gets its own.
TEST(ViewImages, UndistortionCacheFollowsTheSourceContent) {
  SceneFixture f;
  Camera camera = f.add("a.png", solid(16, 12, {9, 99, 199}));
  camera.distortion = {0.05, 0, 0, 0};
  const auto entries = [&] {
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(f.options.undistort_cache_dir))
      count += entry.path().extension() == ".png";
    return count;
  };
  ViewImages(f.scene, f.options).read8(camera);
  write_file_atomically(camera.image_path, read_file(camera.image_path));
  ViewImages(f.scene, f.options).read8(camera);
  EXPECT_EQ(entries(), 1);
  write_png(camera.image_path, solid(16, 12, {200, 10, 10}));
  const Image8 edited = ViewImages(f.scene, f.options).read8(camera);
  EXPECT_EQ(entries(), 2);
  EXPECT_EQ(edited.data[0], 200);
}

}  // namespace
}  // namespace iesrgs
