#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/colmap.hpp"
#include "io/image.hpp"
#include "support/captured_log.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

namespace fs = std::filesystem;
using testing::CapturedLog;
using testing::contains;
using testing::error_message;
using testing::TempDir;
using testing::write_text;

// One camera of each supported model, images named out of id order (one without 2D points, one
// in a subfolder with a space), points with and without tracks. Values such as 1/3 check that
// the text form keeps full double precision.
ColmapModel sample_model() {
  ColmapModel model;
  const auto add_camera = [&](uint32_t id, const char* name, uint64_t w, uint64_t h,
                              std::vector<double> params) {
    model.cameras[id] = {id, name, w, h, std::move(params)};
  };
  add_camera(1, "SIMPLE_PINHOLE", 640, 480, {500.5, 320, 240});
  add_camera(2, "PINHOLE", 800, 600, {700.25, 710.75, 400.5, 299.5});
  add_camera(3, "SIMPLE_RADIAL", 1024, 768, {900.1, 512, 384, -0.0123});
  add_camera(4, "RADIAL", 320, 240, {250, 160.5, 120.25, 0.1, -0.02});
  add_camera(5, "OPENCV", 1920, 1080, {1500.3, 1499.7, 960.2, 539.8, -0.1, 0.05, 0.001, -0.002});

  const double half = std::sqrt(0.5);
  const auto add_image = [&](uint32_t id, const char* name, uint32_t camera,
                             std::array<double, 4> q, std::array<double, 3> t,
                             std::vector<ColmapObservation> observations) {
    model.images[id] = {id, q[0], q[1], q[2], q[3], t[0], t[1], t[2], camera, name, observations};
  };
  // 90 degrees about z: R = [[0,-1,0],[1,0,0],[0,0,1]].
  add_image(10, "frame_c.jpg", 1, {half, 0, 0, half}, {1, 2, 3},
            {{1.5, 2.25, 7}, {100.125, 50.0 / 3, -1}});
  // Not normalized: readers of scenes must normalize (identity rotation).
  add_image(11, "frame_a.jpg", 2, {2, 0, 0, 0}, {0, 0, 5}, {});
  add_image(12, "frame_e.jpg", 3, {0.5, 0.5, 0.5, 0.5}, {-1, 0.1, 1.0 / 3}, {{3, 4, 8}});
  add_image(13, "frame_b.jpg", 4, {1, 0, 0, 0}, {0, 0, 0}, {{0, 0, 7}});
  add_image(14, "frame_d.jpg", 5, {0, 1, 0, 0}, {1e-9, -2e7, 3}, {});
  add_image(15, "left cam/frame_f.png", 5, {1, 0, 0, 0}, {4, 5, 6}, {{7.75, 8.5, -1}});

  model.points = {{7, 0.1, -2.5, 3e-7, 255, 0, 128, 0.75, {{10, 0}, {13, 0}}},
                  {8, 1.0 / 3, 2, -4, 1, 2, 3, 0, {{12, 0}}},
                  {uint64_t(1) << 40, 9, 8, 7, 10, 20, 30, 1.5, {}}};
  return model;
}

void expect_same(const ColmapModel& a, const ColmapModel& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (const auto& [id, ca] : a.cameras) {
    ASSERT_TRUE(b.cameras.count(id)) << "camera " << id;
    const ColmapCamera& cb = b.cameras.at(id);
    EXPECT_EQ(ca.id, cb.id);
    EXPECT_EQ(ca.model, cb.model);
    EXPECT_EQ(ca.width, cb.width);
    EXPECT_EQ(ca.height, cb.height);
    EXPECT_EQ(ca.params, cb.params) << "camera " << id;
  }
  ASSERT_EQ(a.images.size(), b.images.size());
  for (const auto& [id, ia] : a.images) {
    ASSERT_TRUE(b.images.count(id)) << "image " << id;
    const ColmapImage& ib = b.images.at(id);
    EXPECT_EQ(ia.id, ib.id);
    const std::vector<double> pose_a{ia.qw, ia.qx, ia.qy, ia.qz, ia.tx, ia.ty, ia.tz};
    const std::vector<double> pose_b{ib.qw, ib.qx, ib.qy, ib.qz, ib.tx, ib.ty, ib.tz};
    EXPECT_EQ(pose_a, pose_b) << "image " << id;
    EXPECT_EQ(ia.camera_id, ib.camera_id);
    EXPECT_EQ(ia.name, ib.name);
    ASSERT_EQ(ia.observations.size(), ib.observations.size()) << "image " << id;
    for (size_t k = 0; k < ia.observations.size(); ++k) {
      EXPECT_EQ(ia.observations[k].x, ib.observations[k].x);
      EXPECT_EQ(ia.observations[k].y, ib.observations[k].y);
      EXPECT_EQ(ia.observations[k].point3d_id, ib.observations[k].point3d_id);
    }
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t i = 0; i < a.points.size(); ++i) {
    const ColmapPoint& pa = a.points[i];
    const ColmapPoint& pb = b.points[i];
    EXPECT_EQ(pa.id, pb.id);
    EXPECT_EQ(std::vector<double>({pa.x, pa.y, pa.z, pa.error}),
              std::vector<double>({pb.x, pb.y, pb.z, pb.error}));
    EXPECT_EQ(std::vector<int>({pa.r, pa.g, pa.b}), std::vector<int>({pb.r, pb.g, pb.b}));
    ASSERT_EQ(pa.track.size(), pb.track.size()) << "point " << pa.id;
    for (size_t k = 0; k < pa.track.size(); ++k) {
      EXPECT_EQ(pa.track[k].image_id, pb.track[k].image_id);
      EXPECT_EQ(pa.track[k].point2d_index, pb.track[k].point2d_index);
    }
  }
}

// Runs `action`, which must throw Error, and checks the message holds every one of `parts`.
template <typename Action>
void expect_error(Action&& action, std::initializer_list<std::string> parts) {
  const std::string message = testing::error_message(std::forward<Action>(action));
  for (const std::string& part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// Little-endian bytes spelled out field by field, independently of the code under test.
class Bytes {
 public:
  Bytes& u8(uint8_t v) { return raw(v, 1); }
  Bytes& u32(uint32_t v) { return raw(v, 4); }
  Bytes& i32(int32_t v) { return raw(uint32_t(v), 4); }
  Bytes& u64(uint64_t v) { return raw(v, 8); }
  Bytes& i64(int64_t v) { return raw(uint64_t(v), 8); }
  Bytes& f64(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, 8);
    return raw(bits, 8);
  }
  Bytes& text(const std::string& s) {
    bytes_ += s;
    bytes_.push_back('\0');
    return *this;
  }
  const std::string& str() const { return bytes_; }

 private:
  Bytes& raw(uint64_t v, int size) {
    for (int i = 0; i < size; ++i) bytes_.push_back(char((v >> (8 * i)) & 0xff));
    return *this;
  }
  std::string bytes_;
};

// The smallest model with every kind of record, and its three files as COLMAP writes them.
ColmapModel tiny_model() {
  ColmapModel model;
  model.cameras[1] = {1, "PINHOLE", 4, 3, {1, 2, 3, 4}};
  model.images[2] = {2, 1, 0, 0, 0, 5, 6, 7, 1, "a.png", {{0.5, 1.5, -1}}};
  model.points = {{3, 1, 2, 3, 4, 5, 6, 0.5, {{2, 0}}}};
  return model;
}

std::string tiny_cameras_bin() {
  return Bytes().u64(1).u32(1).i32(1).u64(4).u64(3).f64(1).f64(2).f64(3).f64(4).str();
}

std::string tiny_images_bin() {
  Bytes b;
  b.u64(1).u32(2).f64(1).f64(0).f64(0).f64(0).f64(5).f64(6).f64(7).u32(1).text("a.png");
  return b.u64(1).f64(0.5).f64(1.5).i64(-1).str();
}

std::string tiny_points_bin() {
  Bytes b;
  b.u64(1).u64(3).f64(1).f64(2).f64(3).u8(4).u8(5).u8(6).f64(0.5);
  return b.u64(1).u32(2).u32(0).str();
}

TEST(Colmap, BinaryRoundTripKeepsEveryField) {
  TempDir dir;
  const ColmapModel model = sample_model();
  write_colmap_model_binary(dir.path(), model);
  for (const char* file : {"cameras.bin", "images.bin", "points3D.bin"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  expect_same(read_colmap_model(dir.path()), model);
}

TEST(Colmap, TextRoundTripKeepsEveryField) {
  TempDir dir;
  const ColmapModel model = sample_model();
  write_colmap_model_text(dir.path(), model);
  for (const char* file : {"cameras.txt", "images.txt", "points3D.txt"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  expect_same(read_colmap_model(dir.path()), model);
}

TEST(Colmap, BinaryIsPreferredOverText) {
  TempDir dir;
  ColmapModel text_model = sample_model();
  text_model.points.pop_back();
  write_colmap_model_text(dir.path(), text_model);
  write_colmap_model_binary(dir.path(), sample_model());
  expect_same(read_colmap_model(dir.path()), sample_model());
}

TEST(Colmap, BinaryLayoutIsColmaps) {
  TempDir dir;
  write_colmap_model_binary(dir.path(), tiny_model());
  EXPECT_EQ(read_file(dir / "cameras.bin"), tiny_cameras_bin());
  EXPECT_EQ(read_file(dir / "images.bin"), tiny_images_bin());
  EXPECT_EQ(read_file(dir / "points3D.bin"), tiny_points_bin());
  ColmapModel parsed;
  parsed.cameras = parse_colmap_cameras(tiny_cameras_bin(), ColmapEncoding::Binary, "c");
  parsed.images = parse_colmap_images(tiny_images_bin(), ColmapEncoding::Binary, "i");
  parsed.points = parse_colmap_points(tiny_points_bin(), ColmapEncoding::Binary, "p");
  expect_same(parsed, tiny_model());
}

TEST(Colmap, ReadsTextAsColmapWritesIt) {
  // A byte-order mark, CRLF line endings, blank lines, an image whose observation line is empty
  // and one whose observation line is missing at the end of the file.
  const std::string cameras =
      "\xEF\xBB\xBF# Camera list with one line of data per camera:\r\n"
      "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\r\n"
      "# Number of cameras: 1\r\n"
      "\r\n"
      "1 PINHOLE 4 3 1 2 3 4\r\n";
  const std::string images =
      "# Image list with two lines of data per image:\n"
      "2 1 0 0 0 5 6 7 1 a.png\n"
      "0.5 1.5 -1\n"
      "3 1 0 0 0 0 0 0 1 b.png\n"
      "\n"
      "\n"
      "4 1 0 0 0 0 0 0 1 c.png";
  const std::string points = "3 1 2 3 4 5 6 0.5 2 0\n";
  ColmapModel expected = tiny_model();
  expected.images[3] = {3, 1, 0, 0, 0, 0, 0, 0, 1, "b.png", {}};
  expected.images[4] = {4, 1, 0, 0, 0, 0, 0, 0, 1, "c.png", {}};
  ColmapModel parsed;
  parsed.cameras = parse_colmap_cameras(cameras, ColmapEncoding::Text, "c");
  parsed.images = parse_colmap_images(images, ColmapEncoding::Text, "i");
  parsed.points = parse_colmap_points(points, ColmapEncoding::Text, "p");
  expect_same(parsed, expected);
}

TEST(Colmap, ReadsModelsWrittenByColmap) {
  ColmapModel expected = sample_model();
  expected.images[11].qw = 1;  // COLMAP normalized the quaternion
  for (const char* encoding : {"bin", "txt"}) {
    SCOPED_TRACE(encoding);
    ColmapModel model = read_colmap_model(fs::path(IESRGS_TEST_DATA) / "colmap" / encoding);
    std::sort(model.points.begin(), model.points.end(),
              [](const ColmapPoint& a, const ColmapPoint& b) { return a.id < b.id; });
    expect_same(model, expected);
  }
}

// The image files a model lists, empty: a scene's images are looked for as it loads, decoded later.
void write_image_files(const fs::path& root, const ColmapModel& model) {
  for (const auto& [id, image] : model.images) {
    fs::create_directories((root / "images" / image.name).parent_path());
    write_text(root / "images" / image.name, "");
  }
}

// sample_model() as a COLMAP scene folder with the model in `model_dir` below `root`.
void write_sample_scene(const fs::path& root, const std::string& model_dir = "sparse/0") {
  write_colmap_model_binary(root / model_dir, sample_model());
  write_image_files(root, sample_model());
}

void expect_near(const Vec3& a, const Vec3& b) {
  EXPECT_NEAR(a.x, b.x, 1e-9);
  EXPECT_NEAR(a.y, b.y, 1e-9);
  EXPECT_NEAR(a.z, b.z, 1e-9);
}

const Camera& camera_named(const Scene& scene, const char* name) {
  for (const Camera& camera : scene.cameras)
    if (camera.name == name) return camera;
  throw std::runtime_error(std::string("no camera ") + name);
}

TEST(Colmap, SceneCamerasFollowTheModel) {
  TempDir root;
  write_sample_scene(root.path());
  SceneOptions options;
  options.test_every = 2;
  const Scene scene = read_colmap_scene(root.path(), options);
  EXPECT_EQ(scene.format, "colmap");
  EXPECT_FALSE(scene.synthetic);

  // Sorted by image name: a b c d e f; every second one from the first is test.
  std::vector<std::string> names, test_names;
  for (const Camera& camera : scene.cameras) {
    names.push_back(camera.name);
    if (camera.split == Split::Test) test_names.push_back(camera.name);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"frame_a", "frame_b", "frame_c", "frame_d", "frame_e",
                                             "left cam_frame_f"}));
  EXPECT_EQ(test_names, (std::vector<std::string>{"frame_a", "frame_c", "frame_e"}));

  const Camera& c = camera_named(scene, "frame_c");  // R = 90 deg about z, t = (1, 2, 3)
  expect_near(c.center(), {-2, 1, -3});
  expect_near(c.rotation * Vec3{1, 0, 0}, {0, 1, 0});
  EXPECT_EQ(c.image_path, root / "images" / "frame_c.jpg");
  EXPECT_EQ(c.stored.fx, 500.5);
  EXPECT_EQ(c.stored.fy, 500.5);
  EXPECT_EQ(c.stored.cx, 320);
  EXPECT_EQ(c.stored.cy, 240);
  EXPECT_EQ(c.stored.width, 640);
  EXPECT_EQ(c.stored.height, 480);
  EXPECT_FALSE(c.distortion.any());

  const Camera& a = camera_named(scene, "frame_a");  // quaternion (2, 0, 0, 0): identity
  expect_near(a.center(), {0, 0, -5});
  expect_near(a.rotation * Vec3{1, 2, 3}, {1, 2, 3});
  EXPECT_EQ(a.stored.fx, 700.25);
  EXPECT_EQ(a.stored.fy, 710.75);
  EXPECT_EQ(a.stored.cx, 400.5);
  EXPECT_EQ(a.stored.cy, 299.5);

  const Camera& e = camera_named(scene, "frame_e");  // SIMPLE_RADIAL
  EXPECT_EQ(e.stored.fx, 900.1);
  EXPECT_EQ(e.stored.fy, 900.1);
  EXPECT_EQ(e.distortion.k1, -0.0123);
  EXPECT_EQ(e.distortion.k2, 0);

  const Camera& b = camera_named(scene, "frame_b");  // RADIAL
  EXPECT_EQ(b.stored.cx, 160.5);
  EXPECT_EQ(b.distortion.k1, 0.1);
  EXPECT_EQ(b.distortion.k2, -0.02);
  EXPECT_EQ(b.distortion.p1, 0);

  const Camera& d = camera_named(scene, "frame_d");  // OPENCV, 180 deg about x
  expect_near(d.center(), {-1e-9, -2e7, 3});
  EXPECT_EQ(d.stored.fy, 1499.7);
  EXPECT_EQ(d.stored.width, 1920);
  EXPECT_EQ(d.distortion.k1, -0.1);
  EXPECT_EQ(d.distortion.k2, 0.05);
  EXPECT_EQ(d.distortion.p1, 0.001);
  EXPECT_EQ(d.distortion.p2, -0.002);

  EXPECT_EQ(camera_named(scene, "left cam_frame_f").image_path,
            root / "images" / "left cam/frame_f.png");
  for (const Camera& camera : scene.cameras) {
    EXPECT_EQ(camera.intrinsics.fx, camera.stored.fx);
    EXPECT_EQ(camera.intrinsics.width, camera.stored.width);
  }

  ASSERT_EQ(scene.points.positions.size(), 3u);
  expect_near(scene.points.positions[0], {0.1, -2.5, 3e-7});
  EXPECT_EQ(scene.points.colors[0], (std::array<uint8_t, 3>{255, 0, 128}));
  EXPECT_EQ(scene.points.colors[2], (std::array<uint8_t, 3>{10, 20, 30}));
}

TEST(Colmap, DefaultHoldOutIsEveryEighthImage) {
  TempDir root;
  write_sample_scene(root.path());
  const Scene scene = read_colmap_scene(root.path(), SceneOptions{});
  ASSERT_EQ(scene.split(Split::Test).size(), 1u);
  EXPECT_EQ(scene.split(Split::Test).front()->name, "frame_a");
  EXPECT_EQ(scene.split(Split::Train).size(), 5u);
}

// Looked for as the scene loads: not when a stage, perhaps hours on, reaches that view.
TEST(Colmap, AnImageTheModelListsButImagesLacksIsNamedAtLoad) {
  TempDir root;
  write_sample_scene(root.path());
  fs::remove(root / "images" / "frame_e.jpg");
  expect_error([&] { load_scene(root.path()); },
               {(root / "sparse/0/images.bin").string(), "frame_e.jpg not found"});
  // A run at --downscale 2 reads images_2/ alone: a capture may keep only that.
  fs::rename(root / "images", root / "images_2");
  write_text(root / "images_2" / "frame_e.jpg", "");
  SceneOptions half;
  half.downscale = 2;
  EXPECT_EQ(load_scene(root.path(), half).cameras.size(), 6u);
  expect_error([&] { load_scene(root.path()); }, {"frame_a.jpg not found"});
}

TEST(Colmap, LoadSceneDispatchesToColmap) {
  TempDir root;
  write_sample_scene(root.path());
  SceneOptions options;
  options.downscale = 2;
  const Scene scene = load_scene(root.path(), options);
  EXPECT_EQ(scene.format, "colmap");
  ASSERT_EQ(scene.cameras.size(), 6u);
  const Camera& a = camera_named(scene, "frame_a");
  EXPECT_EQ(a.stored.width, 800);
  EXPECT_EQ(a.intrinsics.width, 400);
  EXPECT_DOUBLE_EQ(a.intrinsics.fx, 700.25 / 2);
}

TEST(Colmap, RelativeScenePathsBecomeAbsolute) {
  TempDir root;
  write_sample_scene(root.path());
  const std::filesystem::path relative =
      std::filesystem::relative(root.path(), std::filesystem::current_path());
  ASSERT_TRUE(relative.is_relative());
  const Scene scene = load_scene(relative);
  EXPECT_EQ(scene.root, std::filesystem::absolute(root.path()).lexically_normal());
  EXPECT_TRUE(scene.cameras.front().image_path.is_absolute());
}

TEST(Colmap, ModelDirectlyInSparseIsFound) {
  TempDir root;
  write_sample_scene(root.path(), "sparse");
  EXPECT_EQ(load_scene(root.path()).cameras.size(), 6u);
}

// As 3DGS reads it: a folder with sparse/ is a COLMAP scene, whatever transforms files lie beside
// it (instant-ngp's colmap2nerf writes one, without the SfM points).
TEST(Colmap, SparseComesBeforeAnyTransformsFile) {
  TempDir root;
  write_sample_scene(root.path());
  for (const char* name : {"transforms.json", "transforms_train.json"})
    write_text(root / name, "{}");  // read, either would fail
  const CapturedLog log;
  const Scene scene = load_scene(root.path());
  EXPECT_EQ(scene.format, "colmap");
  EXPECT_EQ(scene.points.positions.size(), sample_model().points.size());
  // Said once, however often the scene is loaded (`run` loads it twice).
  load_scene(root.path());
  EXPECT_EQ(log.count(root.path().string() +
                      ": read as a COLMAP (it holds sparse/) scene; its transforms.json is not "
                      "read (give that file's path to read it instead); its NeRF Synthetic split "
                      "files are not read (they are read from a folder without sparse/)"),
            1u)
      << log.text();
  // And a split file given alone names the folder's format.
  const std::string message = error_message([&] { load_scene(root / "transforms_train.json"); });
  EXPECT_TRUE(contains(message,
                       "holds sparse/ and is read as a COLMAP scene: move the NeRF "
                       "Synthetic files to a folder of their own"))
      << message;
}

// A distorted view renders with the pinhole that sees only what its lens saw (io/undistort.hpp).
TEST(Colmap, DistortedViewsRenderWithThePinholeWithinTheirLens) {
  TempDir root;
  write_sample_scene(root.path());
  SceneOptions options;
  options.downscale = 2;
  const Scene scene = load_scene(root.path(), options);
  const Camera& pincushion = camera_named(scene, "frame_b");  // RADIAL, k1 = 0.1
  EXPECT_GT(pincushion.pinhole.fx, pincushion.stored.fx);
  EXPECT_EQ(pincushion.pinhole.width, pincushion.stored.width);
  EXPECT_DOUBLE_EQ(pincushion.intrinsics.fx, pincushion.pinhole.fx / 2);
  const Camera& barrel = camera_named(scene, "frame_d");  // OPENCV, k1 = -0.1
  EXPECT_LT(barrel.pinhole.fx, barrel.stored.fx);
  const Camera& pinhole = camera_named(scene, "frame_a");  // PINHOLE
  EXPECT_DOUBLE_EQ(pinhole.pinhole.fx, pinhole.stored.fx);
}

// 3DGS's own points3D.ply stands in for points3D.bin; without either, the start is random.
TEST(Colmap, PointsComeFromPoints3DPlyOrTrainingStartsFromRandomPoints) {
  TempDir root;
  write_sample_scene(root.path());
  fs::remove(root / "sparse" / "0" / "points3D.bin");
  EXPECT_TRUE(load_scene(root.path()).points.positions.empty());
  write_text(root / "sparse" / "0" / "points3D.ply",
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
             "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
             "end_header\n1 2 3 255 0 0\n");
  const Scene scene = load_scene(root.path());
  ASSERT_EQ(scene.points.positions.size(), 1u);
  EXPECT_DOUBLE_EQ(scene.points.positions[0].z, 3);
  EXPECT_EQ(scene.points.colors[0][0], 255);
}

// As gsplat reads a model whose images were resized after COLMAP ran.
TEST(Colmap, ACameraTakesTheSizeOfItsImagesWhenTheyAreItsSizeScaled) {
  TempDir root;
  write_sample_scene(root.path());
  fs::create_directories(root / "images");
  write_png(root / "images" / "frame_a.jpg", Image8(400, 300, 3));  // camera 2, 800x600
  const Scene scene = load_scene(root.path());
  const Intrinsics& half = camera_named(scene, "frame_a").stored;
  EXPECT_EQ(half.width, 400);
  EXPECT_EQ(half.height, 300);
  EXPECT_DOUBLE_EQ(half.fx, 700.25 / 2);
  EXPECT_DOUBLE_EQ(half.cy, 299.5 / 2);
  // A third of 800x600 is 266.7 x 200: either side of it rounded, or floored, fits.
  write_png(root / "images" / "frame_a.jpg", Image8(267, 200, 3));
  const CapturedLog log;
  const Scene third = load_scene(root.path());
  EXPECT_DOUBLE_EQ(camera_named(third, "frame_a").stored.fx, 700.25 * 267 / 800);
  EXPECT_DOUBLE_EQ(camera_named(third, "frame_a").stored.fy, 710.75 / 3);
  EXPECT_EQ(log.count("1 of its cameras are not the size of their images but that size scaled; "
                      "their intrinsics are scaled to the images (first: camera 2, 800x600, "
                      "whose frame_a.jpg is 267x200)"),
            1u)
      << log.text();
  // Another shape is no resize, and an unreadable image no size: refused when decoded.
  write_png(root / "images" / "frame_a.jpg", Image8(400, 200, 3));
  const Scene other_shape = load_scene(root.path());
  EXPECT_EQ(camera_named(other_shape, "frame_a").stored.height, 600);
  write_text(root / "images" / "frame_a.jpg", "not an image");
  const Scene unreadable = load_scene(root.path());
  EXPECT_EQ(camera_named(unreadable, "frame_a").stored.height, 600);
}

TEST(Colmap, TruncatedBinaryFilesNameTheFile) {
  TempDir dir;
  write_colmap_model_binary(dir.path(), tiny_model());
  for (const char* name : {"cameras.bin", "images.bin", "points3D.bin"}) {
    const std::string bytes = read_file(dir / name);
    for (size_t size = 0; size < bytes.size(); ++size) {
      SCOPED_TRACE(std::string(name) + " cut at " + std::to_string(size));
      write_text(dir / name, bytes.substr(0, size));
      expect_error([&] { read_colmap_model(dir.path()); }, {(dir / name).string()});
    }
    write_text(dir / name, bytes);
  }
}

TEST(Colmap, AbsurdCountsAreRefusedBeforeAllocating) {
  const uint64_t huge = std::numeric_limits<uint64_t>::max() / 2;
  std::string cameras = tiny_cameras_bin(), images = tiny_images_bin();
  std::string points = tiny_points_bin(), observations = tiny_images_bin();
  cameras.replace(0, 8, Bytes().u64(huge).str());
  images.replace(0, 8, Bytes().u64(huge).str());
  points.replace(0, 8, Bytes().u64(huge).str());
  // The 2D point count follows the name "a.png\0"; the track length follows the point's error.
  const size_t observations_at = observations.find(std::string("a.png") + '\0') + 6;
  observations.replace(observations_at, 8, Bytes().u64(huge).str());
  std::string track = tiny_points_bin();
  track.replace(8 + 8 + 24 + 3 + 8, 8, Bytes().u64(huge).str());
  const auto binary = ColmapEncoding::Binary;
  expect_error([&] { parse_colmap_cameras(cameras, binary, "x/cameras.bin"); },
               {"x/cameras.bin", "cannot fit"});
  expect_error([&] { parse_colmap_images(images, binary, "x/images.bin"); },
               {"x/images.bin", "cannot fit"});
  expect_error([&] { parse_colmap_images(observations, binary, "x/images.bin"); },
               {"x/images.bin", "2D point count"});
  expect_error([&] { parse_colmap_points(points, binary, "x/points3D.bin"); },
               {"x/points3D.bin", "cannot fit"});
  expect_error([&] { parse_colmap_points(track, binary, "x/points3D.bin"); },
               {"x/points3D.bin", "track length"});
}

TEST(Colmap, CorruptBinaryValuesAreRefused) {
  const auto binary = ColmapEncoding::Binary;
  std::string nan_param = tiny_cameras_bin();
  nan_param.replace(8 + 24, 8, Bytes().f64(std::nan("")).str());
  expect_error([&] { parse_colmap_cameras(nan_param, binary, "cameras.bin"); },
               {"cameras.bin", "camera parameter is not finite"});
  std::string huge_param = tiny_cameras_bin();
  huge_param.replace(8 + 24, 8, Bytes().f64(1e300).str());
  expect_error([&] { parse_colmap_cameras(huge_param, binary, "cameras.bin"); },
               {"cameras.bin", "camera parameter 1e+300 is beyond the single-precision range"});
  std::string unknown_model = tiny_cameras_bin();
  unknown_model.replace(12, 4, Bytes().i32(42).str());
  expect_error([&] { parse_colmap_cameras(unknown_model, binary, "cameras.bin"); },
               {"cameras.bin", "unknown model id 42"});
  expect_error([&] { parse_colmap_cameras(tiny_cameras_bin() + "x", binary, "cameras.bin"); },
               {"cameras.bin", "1 unexpected bytes"});
  std::string twice = tiny_cameras_bin().substr(8);
  twice = Bytes().u64(2).str() + twice + twice;
  expect_error([&] { parse_colmap_cameras(twice, binary, "cameras.bin"); },
               {"cameras.bin", "camera id 1 appears twice"});
  std::string bad_id = tiny_images_bin();
  bad_id.replace(bad_id.size() - 8, 8, Bytes().i64(-5).str());
  expect_error([&] { parse_colmap_images(bad_id, binary, "images.bin"); },
               {"images.bin", "3D point id -5 is negative"});
  std::string empty_name = tiny_images_bin();
  empty_name.erase(empty_name.find("a.png"), 5);
  expect_error([&] { parse_colmap_images(empty_name, binary, "images.bin"); },
               {"images.bin", "image name is empty"});
}

TEST(Colmap, MalformedTextNamesFileAndLine) {
  const auto text = ColmapEncoding::Text;
  const std::string header = "# a comment\n";
  expect_error([&] { parse_colmap_cameras(header + "1 PINHOLE 4 x 1 2 3 4\n", text, "c.txt"); },
               {"c.txt: line 2", "HEIGHT 'x' is not a valid number"});
  expect_error([&] { parse_colmap_cameras(header + "1 PINHOLE 4 3 1 2 3\n", text, "c.txt"); },
               {"c.txt: line 2", "PINHOLE takes 4 parameters, found 3"});
  expect_error([&] { parse_colmap_cameras("1 PINHOLE 4 3 1 nan 3 4\n", text, "c.txt"); },
               {"c.txt: line 1", "not finite"});
  expect_error([&] { parse_colmap_cameras("1 FANCY 4 3 1\n", text, "c.txt"); },
               {"c.txt: line 1", "unknown camera model 'FANCY'"});
  expect_error([&] { parse_colmap_cameras("1 PINHOLE\n", text, "c.txt"); },
               {"c.txt: line 1", "missing WIDTH"});
  expect_error([&] { parse_colmap_images("2 1 0 0 0 5 6 7 1\n\n", text, "i.txt"); },
               {"i.txt: line 1", "NAME is empty"});
  expect_error([&] { parse_colmap_images("2 1 0 0 0 5 6 7 1 a.png\n0.5 1.5\n", text, "i.txt"); },
               {"i.txt: line 2", "missing POINT3D_ID", "each image takes two lines"});
  // Without the 2D points' lines, the second image's pose is read as points.
  expect_error(
      [&] {
        parse_colmap_images("1 1 0 0 0 0 0 0 1 a.png\n2 1 0 0 0 5 6 7 1 b.png\n", text, "i.txt");
      },
      {"i.txt: line 2", "2D point X 'b.png' is not", "each image takes two lines"});
  expect_error([&] { parse_colmap_points("3 1 2 3 4 5 256 0.5\n", text, "p.txt"); },
               {"p.txt: line 1", "B '256' is not a valid number"});
  expect_error([&] { parse_colmap_points("3 1 2 3 4 5 6 0.5 2\n", text, "p.txt"); },
               {"p.txt: line 1", "missing track POINT2D_IDX"});
}

TEST(Colmap, UnsupportedCameraModelIsNamed) {
  TempDir root;
  ColmapModel model = sample_model();
  model.cameras[3] = {3, "FOV", 100, 100, {1, 1, 50, 50, 0.5}};
  write_colmap_model_text(root / "sparse/0", model);
  expect_error([&] { load_scene(root.path()); },
               {(root / "sparse/0/cameras.txt").string(), "FOV",
                "SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV, "
                "SIMPLE_FISHEYE, FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE, OPENCV_FISHEYE"});
}

// A fisheye's terms bend the ray's angle, and its views render with the pinhole within it.
TEST(Colmap, FisheyeCamerasKeepTheirTerms) {
  TempDir root;
  ColmapModel model = sample_model();
  model.cameras[5] = {
      5, "OPENCV_FISHEYE", 1920, 1080, {1500, 1490, 960, 540, 0.1, -0.02, 0.003, -0.0004}};
  model.cameras[3] = {3, "RADIAL_FISHEYE", 1024, 768, {900, 512, 384, 0.05, 0.01}};
  model.cameras[1] = {1, "SIMPLE_FISHEYE", 640, 480, {500, 320, 240}};
  write_colmap_model_text(root / "sparse/0", model);
  write_image_files(root.path(), model);
  const Scene scene = load_scene(root.path());
  const Distortion& opencv = camera_named(scene, "frame_d").distortion;
  EXPECT_TRUE(opencv.fisheye);
  EXPECT_EQ(opencv.k1, 0.1);
  EXPECT_EQ(opencv.k2, -0.02);
  EXPECT_EQ(opencv.k3, 0.003);
  EXPECT_EQ(opencv.k4, -0.0004);
  EXPECT_EQ(opencv.p1, 0);
  const Camera& radial = camera_named(scene, "frame_e");
  EXPECT_TRUE(radial.distortion.fisheye);
  EXPECT_EQ(radial.distortion.k1, 0.05);
  EXPECT_EQ(radial.distortion.k2, 0.01);
  EXPECT_EQ(radial.stored.fy, 900);
  // Equidistant alone: still a lens to undo. Its image holds more at its edges than a pinhole of
  // its focal length: the pinhole within it has shorter ones.
  const Camera& simple = camera_named(scene, "frame_c");
  EXPECT_TRUE(simple.distortion.fisheye);
  EXPECT_EQ(simple.distortion.k1, 0);
  EXPECT_LT(simple.pinhole.fx, simple.stored.fx);
}

TEST(Colmap, FullOpencvKeepsItsRationalTerms) {
  TempDir root;
  ColmapModel model = sample_model();
  model.cameras[5] = {
      5,
      "FULL_OPENCV",
      1920,
      1080,
      {1500.3, 1499.7, 960.2, 539.8, -0.1, 0.05, 0.001, -0.002, 0.01, 0.2, -0.03, 0.004}};
  write_colmap_model_text(root / "sparse/0", model);
  write_image_files(root.path(), model);
  const Distortion d = camera_named(read_colmap_scene(root.path(), {}), "frame_d").distortion;
  EXPECT_EQ(d.k1, -0.1);
  EXPECT_EQ(d.p2, -0.002);
  EXPECT_EQ(d.k3, 0.01);
  EXPECT_EQ(d.k4, 0.2);
  EXPECT_EQ(d.k5, -0.03);
  EXPECT_EQ(d.k6, 0.004);
}

TEST(Colmap, UnusedCameraOfAnyModelIsIgnored) {
  TempDir root;
  ColmapModel model = sample_model();
  model.cameras[9] = {9, "FOV", 100, 100, {1, 1, 50, 50, 0.5}};
  write_colmap_model_text(root / "sparse/0", model);
  write_image_files(root.path(), model);
  EXPECT_EQ(load_scene(root.path()).cameras.size(), model.images.size());
}

TEST(Colmap, ImageWithMissingCameraIsRefused) {
  TempDir root;
  ColmapModel model = sample_model();
  model.images[11].camera_id = 99;
  write_colmap_model_binary(root / "sparse/0", model);
  expect_error([&] { load_scene(root.path()); },
               {(root / "sparse/0/images.bin").string(), "refers to camera 99"});
}

TEST(Colmap, ImplausibleCamerasAreRefused) {
  TempDir root;
  ColmapModel model = sample_model();
  model.cameras[1].width = 0;
  write_colmap_model_binary(root / "sparse/0", model);
  expect_error([&] { read_colmap_scene(root.path(), {}); },
               {"cameras.bin", "camera 1: implausible image size 0x480"});
  model = sample_model();
  model.cameras[2].params[1] = -5;
  write_colmap_model_binary(root / "sparse/0", model);
  expect_error([&] { read_colmap_scene(root.path(), {}); },
               {"cameras.bin", "camera 2: focal length must be positive"});
  model = sample_model();
  model.images[10].qw = model.images[10].qz = 0;
  write_colmap_model_binary(root / "sparse/0", model);
  expect_error([&] { read_colmap_scene(root.path(), {}); },
               {"images.bin", "'frame_c.jpg': rotation quaternion cannot be normalized"});
  model = sample_model();
  model.images[13].name = "frame_a.jpg";  // one file posed twice
  write_colmap_model_binary(root / "sparse/0", model);
  expect_error([&] { read_colmap_scene(root.path(), {}); },
               {"images.bin", "image 'frame_a.jpg' is listed twice (ids 11 and 13)"});
}

TEST(Colmap, MissingFilesAreNamed) {
  TempDir root;
  fs::create_directories(root / "sparse/0");
  expect_error([&] { load_scene(root.path()); },
               {(root / "sparse/0").string(), "neither cameras.bin nor cameras.txt"});
  write_colmap_model_binary(root / "sparse/0", sample_model());
  fs::remove(root / "sparse/0/images.bin");
  expect_error([&] { load_scene(root.path()); },
               {(root / "sparse/0/images.bin").string(), "file not found"});
}

TEST(Colmap, WritersRefuseWhatCannotBeReadBack) {
  TempDir dir;
  ColmapModel model = tiny_model();
  model.cameras[1].params.pop_back();
  expect_error([&] { write_colmap_model_binary(dir.path(), model); },
               {(dir / "cameras.bin").string(), "PINHOLE takes 4 parameters, got 3"});
  model = tiny_model();
  model.cameras[1].model = "FANCY";
  expect_error([&] { write_colmap_model_text(dir.path(), model); },
               {(dir / "cameras.txt").string(), "unknown model 'FANCY'"});
  model = tiny_model();
  model.images[2].name = "two\nlines.png";
  expect_error([&] { write_colmap_model_text(dir.path(), model); },
               {(dir / "images.txt").string(), "contains a control character"});
}

}  // namespace
}  // namespace iesrgs
