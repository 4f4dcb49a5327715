#include "io/transforms.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "support/captured_log.hpp"
#include "support/expect_error.hpp"
#include "support/projection.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::contains;
using testing::error_message;
using testing::project;
using testing::TempDir;
using testing::write_text;

// OpenGL camera-to-world: a camera at `center` with identity orientation (looking down -z).
json identity_pose(double x, double y, double z) {
  return {{1, 0, 0, x}, {0, 1, 0, y}, {0, 0, 1, z}, {0, 0, 0, 1}};
}

json frame(const std::string& file_path) {
  return {{"file_path", file_path}, {"transform_matrix", identity_pose(0, 0, 4)}};
}

// A valid nerfstudio scene of 8x6 pinhole images that need not exist (w and h are given).
json nerfstudio_document() {
  return {{"fl_x", 10.0},
          {"w", 8},
          {"h", 6},
          {"frames", {frame("images/b.png"), frame("images/a.png")}}};
}

void write_png_file(const fs::path& path, int width, int height) {
  write_png(path, Image8(width, height, 3));
}

// Writes `document` as transforms.json into `dir`, with an 8x6 PNG for every frame.
fs::path write_nerfstudio_scene(const TempDir& dir, const json& document) {
  for (const json& f : document["frames"])
    write_png_file(dir.path() / f["file_path"].get<std::string>(), 8, 6);
  write_text(dir / "transforms.json", document.dump());
  return dir / "transforms.json";
}

Scene parse_in_memory(const json& document, const SceneOptions& options = {}) {
  return parse_nerfstudio_transforms(
      document.dump(), "/data/transforms.json", options,
      [](const fs::path&) {
        return ImageHeader{64, 48};
      },
      [](const fs::path& path) {
        PointCloud points;  // one point, whose colour says which file was asked for
        points.positions.push_back({1, 2, 3});
        points.colors.push_back({uint8_t(path.string().size()), 0, 0});
        return points;
      });
}

TEST(BlenderScene, ReadsNerfSyntheticLego) {
  const fs::path root = fs::path(IESRGS_SHARED_DATA) / "nerf_synthetic" / "lego";
  if (!fs::exists(root / "transforms_train.json")) GTEST_SKIP() << "no lego scene at " << root;
  const Scene scene = read_blender_scene(root, {});
  EXPECT_EQ(scene.format, "blender");
  EXPECT_TRUE(scene.synthetic);
  ASSERT_EQ(scene.split(Split::Train).size(), 100u);
  ASSERT_EQ(scene.split(Split::Test).size(), 200u);
  EXPECT_EQ(scene.cameras.front().name, "r_0");
  EXPECT_EQ(scene.cameras.front().image_path, root / "train" / "r_0.png");
  const double focal = 0.5 * 800 / std::tan(0.5 * 0.6911112070083618);
  for (const Camera& camera : scene.cameras) {
    SCOPED_TRACE(camera.image_path.string());
    EXPECT_EQ(camera.intrinsics.width, 800);
    EXPECT_EQ(camera.intrinsics.height, 800);
    EXPECT_NEAR(camera.intrinsics.fx, focal, 1e-9);
    EXPECT_DOUBLE_EQ(camera.intrinsics.cx, 400);
    EXPECT_FALSE(camera.distortion.any());
    EXPECT_NEAR(camera.center().norm(), 4.03, 0.01);
    // Every camera looks at the object at the origin.
    const auto [u, v] = project(camera, {0, 0, 0});
    EXPECT_NEAR(u, 400, 1);
    EXPECT_NEAR(v, 400, 1);
  }
}

TEST(BlenderScene, WithoutTestFileHasNoTestCameras) {
  TempDir dir;
  write_png_file(dir / "train" / "r_0.png", 20, 10);
  write_png_file(dir / "train" / "r_1.jpeg.png", 20, 10);
  write_png_file(dir / "train" / "r_2.001.png", 20, 10);
  const json document = {
      {"camera_angle_x", 2 * std::atan(0.5)},
      {"frames", {frame("./train/r_0"), frame("./train/r_1.jpeg.png"), frame("./train/r_2.001")}}};
  write_text(dir / "transforms_train.json", document.dump());
  const Scene scene = read_blender_scene(dir.path(), {});
  ASSERT_EQ(scene.cameras.size(), 3u);
  EXPECT_TRUE(scene.split(Split::Test).empty());
  EXPECT_EQ(scene.cameras[0].image_path, dir / "train" / "r_0.png");  // ".png" appended
  EXPECT_EQ(scene.cameras[1].image_path, dir / "train" / "r_1.jpeg.png");
  // As 3DGS reads it: ".png" appended to what only looks like an extension.
  EXPECT_EQ(scene.cameras[2].image_path, dir / "train" / "r_2.001.png");
  const Intrinsics& k = scene.cameras[0].stored;
  EXPECT_EQ(k.width, 20);
  EXPECT_EQ(k.height, 10);
  EXPECT_NEAR(k.fx, 20, 1e-9);  // tan(fov / 2) = 0.5 across 20 pixels
  EXPECT_NEAR(k.fy, 20, 1e-9);
  EXPECT_DOUBLE_EQ(k.cy, 5);
}

TEST(BlenderScene, TestFileAloneHasOnlyTestCameras) {
  TempDir dir;
  write_png_file(dir / "test" / "r_0.png", 20, 10);
  const json document = {{"camera_angle_x", 0.7}, {"frames", {frame("./test/r_0")}}};
  write_text(dir / "transforms_test.json", document.dump());
  const Scene scene = read_blender_scene(dir.path(), {});
  ASSERT_EQ(scene.cameras.size(), 1u);
  EXPECT_EQ(scene.cameras[0].split, Split::Test);
  EXPECT_TRUE(is_scene(dir.path()));
}

TEST(BlenderScene, MissingBothFilesIsAnError) {
  TempDir dir;
  EXPECT_FALSE(is_scene(dir.path()));
  const std::string message = error_message([&] { read_blender_scene(dir.path(), {}); });
  EXPECT_NE(message.find("transforms_train.json"), std::string::npos) << message;
  EXPECT_NE(message.find("not found (nor transforms_test.json)"), std::string::npos) << message;
}

TEST(BlenderScene, MissingImageIsAnError) {
  TempDir dir;
  write_png_file(dir / "train" / "r_0.png", 20, 10);
  const json document = {{"camera_angle_x", 0.7}, {"frames", {frame("train/r_0"), frame("r_9")}}};
  write_text(dir / "transforms_train.json", document.dump());
  const std::string message = error_message([&] { read_blender_scene(dir.path(), {}); });
  EXPECT_NE(message.find("transforms_train.json"), std::string::npos) << message;
  EXPECT_NE(message.find("r_9.png not found"), std::string::npos) << message;
}

TEST(NerfstudioScene, ReadsInstantNgpFox) {
  const fs::path json_path = fs::path(IESRGS_SHARED_DATA) / "fox" / "transforms.json";
  if (!fs::exists(json_path)) GTEST_SKIP() << "no fox scene at " << json_path;
  const Scene scene = read_nerfstudio_scene(json_path, {});
  EXPECT_EQ(scene.format, "nerfstudio");
  EXPECT_FALSE(scene.synthetic);
  ASSERT_EQ(scene.cameras.size(), 67u);
  EXPECT_EQ(scene.split(Split::Test).size(), 9u);  // frames 0, 8, ..., 64
  const Camera& first = scene.cameras.front();
  EXPECT_EQ(first.name, "0001");
  EXPECT_EQ(first.split, Split::Test);
  EXPECT_EQ(scene.cameras[1].split, Split::Train);
  EXPECT_EQ(first.stored.width, 1080);
  EXPECT_EQ(first.stored.height, 1920);
  EXPECT_DOUBLE_EQ(first.stored.fx, 1375.52);
  EXPECT_DOUBLE_EQ(first.stored.fy, 1374.49);
  EXPECT_DOUBLE_EQ(first.stored.cx, 554.558);
  EXPECT_DOUBLE_EQ(first.stored.cy, 965.268);
  EXPECT_DOUBLE_EQ(first.distortion.k1, 0.0578421);
  EXPECT_DOUBLE_EQ(first.distortion.k2, -0.0805099);
  EXPECT_DOUBLE_EQ(first.distortion.p1, -0.000980296);
  EXPECT_DOUBLE_EQ(first.distortion.p2, 0.00015575);
  // The center is the matrix's last column; OpenCV's forward axis is OpenGL's -z column.
  // (up to the stored rotation's rounding, about 1e-6).
  EXPECT_NEAR(first.center().x, 3.168359405609479, 1e-5);
  EXPECT_NEAR(first.center().z, -0.9791660699008925, 1e-5);
  const Vec3 forward = first.rotation.transposed() * Vec3{0, 0, 1};
  EXPECT_NEAR(forward.x, -0.4420900262071262, 1e-12);
  EXPECT_NEAR(forward.y, 0.8940689141475064, 1e-12);
}

TEST(NerfstudioScene, SortsFramesByFilePathAndHoldsOutEveryKth) {
  json document = nerfstudio_document();
  document["frames"] = json::array();
  for (const char* name : {"e", "c", "a", "d", "b"})
    document["frames"].push_back(frame(std::string("images/") + name + ".jpg"));
  SceneOptions options;
  options.test_every = 3;
  const Scene scene = parse_in_memory(document, options);
  std::string names, splits;
  for (const Camera& camera : scene.cameras) {
    names += camera.name;
    splits += camera.split == Split::Test ? 'T' : '-';
  }
  EXPECT_EQ(names, "abcde");
  EXPECT_EQ(splits, "T--T-");
  EXPECT_EQ(scene.cameras[0].image_path, fs::path("/data/images/a.jpg"));
}

// nerfstudio trains only where a frame's mask is white: a scene with masks is told they are not.
TEST(NerfstudioScene, MasksAreSaidToBeUnread) {
  TempDir dir;
  json document = nerfstudio_document();
  document["frames"][1]["mask_path"] = "masks/a.png";
  const fs::path json_path = write_nerfstudio_scene(dir, document);
  const testing::CapturedLog log;
  parse_nerfstudio_transforms(
      document.dump(), json_path, {},
      [](const fs::path&) {
        return ImageHeader{8, 6};
      },
      [](const fs::path&) { return PointCloud{}; });
  EXPECT_EQ(log.count(json_path.string() +
                      ": frames' mask_path is not read: every pixel of their images is trained "
                      "on and scored"),
            1u)
      << log.text();
}

// The camera names and splits of a scene, in order: "a-" for a training view a, "bT" for a test
// view b.
std::string names_and_splits(const Scene& scene) {
  std::string out;
  for (const Camera& camera : scene.cameras)
    out += camera.name + (camera.split == Split::Test ? "T" : "-");
  return out;
}

TEST(NerfstudioScene, SplitListsSetTheSplitAsNerfstudio) {
  json document = nerfstudio_document();
  document["frames"] = json::array();
  for (const char* name : {"e", "c", "a", "d", "b"})
    document["frames"].push_back(frame(std::string("images/") + name + ".jpg"));
  // Names resolve as file_path does: "./images/c.jpg" is "images/c.jpg".
  document["train_filenames"] = {"images/a.jpg", "./images/c.jpg", "images/e.jpg"};
  document["val_filenames"] = {"images/b.jpg"};
  EXPECT_EQ(names_and_splits(parse_in_memory(document)), "a-c-e-bT");  // d is in neither
  document["test_filenames"] = {"images/d.jpg", "images/a.jpg"};
  EXPECT_EQ(names_and_splits(parse_in_memory(document)), "a-c-e-aTdT");

  document["test_filenames"] = {"images/f.jpg"};
  EXPECT_NE(error_message([&] {
              parse_in_memory(document);
            }).find("\"test_filenames\" names /data/images/f.jpg, which no frame's file_path does"),
            std::string::npos);
  document["train_filenames"] = json::array();
  EXPECT_NE(error_message([&] {
              parse_in_memory(document);
            }).find("\"train_filenames\" is empty: nothing to train on"),
            std::string::npos);
  document.erase("train_filenames");
  EXPECT_NE(error_message([&] {
              parse_in_memory(document);
            }).find("\"test_filenames\" without \"train_filenames\""),
            std::string::npos);
}

TEST(NerfstudioScene, PlyFilePathGivesThePoints) {
  json document = nerfstudio_document();
  EXPECT_TRUE(parse_in_memory(document).points.positions.empty());
  document["ply_file_path"] = "./sparse_pc.ply";  // "/data/sparse_pc.ply", 19 characters
  const PointCloud points = parse_in_memory(document).points;
  ASSERT_EQ(points.positions.size(), 1u);
  EXPECT_EQ(points.colors[0][0], 19);

  // Read from a file: an ascii cloud as nerfstudio's ns-process-data writes it.
  TempDir dir;
  write_text(dir / "sparse_pc.ply",
             "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
             "property float z\nproperty uint8 red\nproperty uint8 green\nproperty uint8 blue\n"
             "end_header\n0.5 -1 2 255 128 0\n3 4 5 1 2 3\n");
  const fs::path json_path = write_nerfstudio_scene(dir, document);
  const Scene scene = read_nerfstudio_scene(json_path, {});
  ASSERT_EQ(scene.points.positions.size(), 2u);
  EXPECT_EQ(scene.points.positions[0].y, -1);
  EXPECT_EQ(scene.points.colors[0], (std::array<uint8_t, 3>{255, 128, 0}));

  // As nerfstudio, a point file that is not there leaves random points to start from; one that
  // is there must be readable.
  write_text(dir / "sparse_pc.ply", "ply\nformat ascii 1.0\nend_header\n");
  const std::string message = error_message([&] { read_nerfstudio_scene(json_path, {}); });
  EXPECT_NE(message.find(json_path.string() + ": \"ply_file_path\": " +
                         (dir / "sparse_pc.ply").string() + ": the header has no vertex element"),
            std::string::npos)
      << message;
  fs::remove(dir / "sparse_pc.ply");
  EXPECT_TRUE(read_nerfstudio_scene(json_path, {}).points.positions.empty());
}

TEST(NerfstudioScene, ThreeRowMatrixIsAPose) {
  json document = nerfstudio_document();
  const Camera four = parse_in_memory(document).cameras[0];
  document["frames"][0]["transform_matrix"].erase(3);
  document["frames"][1]["transform_matrix"].erase(3);
  const Camera three = parse_in_memory(document).cameras[0];
  EXPECT_EQ(three.rotation.m, four.rotation.m);
  EXPECT_EQ(three.translation.z, four.translation.z);
}

TEST(NerfstudioScene, FrameKeysOverrideSceneIntrinsics) {
  json document = nerfstudio_document();
  document["fl_y"] = 12.0;
  document["frames"][0]["fl_x"] = 20.0;
  document["frames"][0]["cx"] = 3.5;
  const Scene scene = parse_in_memory(document);
  const Intrinsics& overridden = scene.cameras[1].stored;  // images/b.png sorts second
  EXPECT_DOUBLE_EQ(overridden.fx, 20);
  EXPECT_DOUBLE_EQ(overridden.fy, 12);
  EXPECT_DOUBLE_EQ(overridden.cx, 3.5);
  EXPECT_DOUBLE_EQ(overridden.cy, 3);  // absent: the image center
  EXPECT_DOUBLE_EQ(scene.cameras[0].stored.fx, 10);

  // A frame's field of view overrides the scene's focal in pixels too.
  document["frames"][1]["camera_angle_x"] = 2 * std::atan(0.5);  // 8 pixels wide: fx = 8
  EXPECT_NEAR(parse_in_memory(document).cameras[0].stored.fx, 8, 1e-9);
}

TEST(NerfstudioScene, FieldOfViewAndImageHeaderFillMissingIntrinsics) {
  const json document = {{"camera_angle_x", 2 * std::atan(0.5)}, {"frames", {frame("a.png")}}};
  const Intrinsics k = parse_in_memory(document).cameras[0].stored;
  EXPECT_EQ(k.width, 64);  // from the image header
  EXPECT_EQ(k.height, 48);
  EXPECT_NEAR(k.fx, 64, 1e-9);
  EXPECT_NEAR(k.fy, 64, 1e-9);  // one field of view: square pixels
  EXPECT_DOUBLE_EQ(k.cx, 32);

  json both = document;
  both["camera_angle_y"] = 2 * std::atan(0.25);
  EXPECT_NEAR(parse_in_memory(both).cameras[0].stored.fy, 96, 1e-9);
}

TEST(NerfstudioScene, ReadsImageSizeFromTheFilesWhenAbsent) {
  TempDir dir;
  json document = nerfstudio_document();
  document.erase("w");
  document.erase("h");
  const Scene scene = read_nerfstudio_scene(write_nerfstudio_scene(dir, document), {});
  EXPECT_EQ(scene.cameras[0].stored.width, 8);
  EXPECT_EQ(scene.cameras[0].stored.height, 6);
}

// As instant-ngp reads them: a file_path without its extension, or with Windows separators.
TEST(NerfstudioScene, FramePathsWithoutExtensionOrWithBackslashesAreFound) {
  TempDir dir;
  write_png_file(dir / "images" / "a.jpg", 8, 6);
  write_png_file(dir / "images" / "b.png", 8, 6);
  json document = nerfstudio_document();
  document["frames"] = {frame("images/a"), frame("images\\b.png")};
  write_text(dir / "transforms.json", document.dump());
  const Scene scene = read_nerfstudio_scene(dir / "transforms.json", {});
  ASSERT_EQ(scene.cameras.size(), 2u);
  EXPECT_EQ(scene.cameras[0].image_path, dir / "images" / "a.jpg");
  EXPECT_EQ(scene.cameras[1].image_path, dir / "images" / "b.png");
}

TEST(NerfstudioScene, CameraModels) {
  json document = nerfstudio_document();
  EXPECT_FALSE(parse_in_memory(document).cameras[0].distortion.any());

  document["k1"] = 0.1;  // instant-ngp names no camera model
  document["p2"] = -0.01;
  document["is_fisheye"] = false;  // as instant-ngp's colmap2nerf writes it
  Distortion d = parse_in_memory(document).cameras[0].distortion;
  EXPECT_DOUBLE_EQ(d.k1, 0.1);
  EXPECT_DOUBLE_EQ(d.k2, 0);
  EXPECT_DOUBLE_EQ(d.p2, -0.01);
  EXPECT_FALSE(d.beyond_opencv());

  // As nerfstudio: the coefficients apply under any perspective model's name, k3 included.
  document["k3"] = 0.02;
  for (const char* model : {"SIMPLE_PINHOLE", "PINHOLE", "SIMPLE_RADIAL", "RADIAL", "OPENCV"}) {
    document["camera_model"] = model;
    d = parse_in_memory(document).cameras[0].distortion;
    EXPECT_DOUBLE_EQ(d.k1, 0.1) << model;
    EXPECT_DOUBLE_EQ(d.k3, 0.02) << model;
  }
  // nerfstudio's fisheye: k1..k4 on the ray's angle, k4 its own; tangential terms are refused.
  document["camera_model"] = "OPENCV_FISHEYE";
  document["k4"] = 0.004;
  EXPECT_TRUE(contains(error_message([&] { parse_in_memory(document); }),
                       "\"p2\" is not supported by OPENCV_FISHEYE"));
  document.erase("p2");
  d = parse_in_memory(document).cameras[0].distortion;
  EXPECT_TRUE(d.fisheye);
  EXPECT_DOUBLE_EQ(d.k1, 0.1);
  EXPECT_DOUBLE_EQ(d.k4, 0.004);
}

// A rig's folders keep the same file names: the folder below the one all images share stays in
// the name, as COLMAP scenes name their views.
TEST(NerfstudioScene, ViewsAreNamedAfterTheirPathBelowTheFolderAllImagesShare) {
  json document = nerfstudio_document();
  EXPECT_EQ(parse_in_memory(document).cameras[0].name, "a");
  document["frames"] = {frame("images/cam1/0001.jpg"), frame("images/cam0/0001.jpg"),
                        frame("images/cam0/sub/0002.jpg")};
  std::vector<std::string> names;
  for (const Camera& camera : parse_in_memory(document).cameras) names.push_back(camera.name);
  EXPECT_EQ(names, (std::vector<std::string>{"cam0_0001", "cam0_sub_0002", "cam1_0001"}));
}

TEST(NerfstudioScene, MissingImageIsAnError) {
  TempDir dir;
  const fs::path json_path = write_nerfstudio_scene(dir, nerfstudio_document());
  fs::remove(dir / "images" / "a.png");
  const std::string message = error_message([&] { read_nerfstudio_scene(json_path, {}); });
  EXPECT_EQ(message.rfind(json_path.string() + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("a.png not found"), std::string::npos) << message;
}

struct BadInput {
  std::string what;
  std::function<std::string()> text;  // the transforms.json to write
  std::vector<std::string> expected;  // pieces of the message
};

// `change` applied to a valid document.
std::function<std::string()> edited(std::function<void(json&)> change) {
  return [change] {
    json document = nerfstudio_document();
    change(document);
    return document.dump();
  };
}

std::function<std::string()> raw(std::string text) {
  return [text] { return text; };
}

TEST(NerfstudioScene, BadInputGivesOneLineErrorNamingFileAndProblem) {
  const std::string valid = nerfstudio_document().dump();
  const std::vector<BadInput> cases = {
      {"truncated",
       raw(valid.substr(0, valid.size() - 1)),
       {"malformed JSON at byte " + std::to_string(valid.size()), "unexpected end of input"}},
      {"malformed", raw("{\"fl_x\": 10,, }"), {"malformed JSON at byte 13"}},
      {"number overflow", raw("{\"fl_x\": 1e999}"), {"invalid JSON (number overflow", "1e999"}},
      {"not an object", raw("[1, 2]"), {"top level is not a JSON object"}},
      {"no frames key", edited([](json& d) { d.erase("frames"); }), {"missing \"frames\""}},
      {"frames not array", edited([](json& d) { d["frames"] = 3; }), {"\"frames\" must be"}},
      {"no frames", edited([](json& d) { d["frames"] = json::array(); }), {"no frames"}},
      {"frame not object",
       edited([](json& d) { d["frames"][1] = "x"; }),
       {"frame 1: not a JSON object"}},
      {"no file_path",
       edited([](json& d) { d["frames"][1].erase("file_path"); }),
       {"frame 1: missing \"file_path\""}},
      {"file_path not string",
       edited([](json& d) { d["frames"][0]["file_path"] = 7; }),
       {"frame 0: \"file_path\" must be a non-empty string"}},
      {"control character",
       edited([](json& d) { d["frames"][0]["file_path"] = "a\nb.png"; }),
       {"frame 0: \"file_path\" contains control characters"}},
      {"no matrix",
       edited([](json& d) { d["frames"][1].erase("transform_matrix"); }),
       {"frame 1: missing \"transform_matrix\""}},
      {"2x4 matrix",
       edited([](json& d) {
         d["frames"][1]["transform_matrix"].erase(3);
         d["frames"][1]["transform_matrix"].erase(2);
       }),
       {"frame 1: \"transform_matrix\" must be a 4x4 (or 3x4) array of numbers"}},
      {"string entry",
       edited([](json& d) { d["frames"][0]["transform_matrix"][2][1] = "0"; }),
       {"frame 0: \"transform_matrix\" must be a 4x4 (or 3x4) array of numbers"}},
      {"split list not a list",
       edited([](json& d) { d["train_filenames"] = "images/a.png"; }),
       {"\"train_filenames\" must be an array of file names"}},
      {"huge entry",
       edited([](json& d) { d["frames"][0]["transform_matrix"][0][0] = 1e300; }),
       {"frame 0: \"transform_matrix\" does not hold a rotation"}},
      {"mirrored",
       edited([](json& d) { d["frames"][0]["transform_matrix"][0][0] = -1; }),
       {"frame 0: \"transform_matrix\" does not hold a rotation"}},
      {"position overflow",
       edited([](json& d) {
         const double c = std::sqrt(0.5);  // a 45 degree turn adds two huge coordinates
         d["frames"][0]["transform_matrix"] = {
             {c, -c, 0, 1.7e308}, {c, c, 0, 1.7e308}, {0, 0, 1, 0}, {0, 0, 0, 1}};
       }),
       {"frame 0: \"transform_matrix\" position is out of range"}},
      {"position beyond float",
       edited([](json& d) { d["frames"][0]["transform_matrix"][0][3] = 1e300; }),
       {"frame 0: \"transform_matrix\" position is out of range"}},
      {"no focal",
       edited([](json& d) { d.erase("fl_x"); }),
       {"frame 0: missing \"fl_x\" (or \"camera_angle_x\")"}},
      {"focal wrong type",
       edited([](json& d) { d["frames"][1]["fl_x"] = "10"; }),
       {"frame 1: \"fl_x\" must be a number"}},
      {"scene key wrong type",
       edited([](json& d) { d["fl_x"] = json::array(); }),
       {"transforms.json: \"fl_x\" must be a number"}},
      {"negative focal", edited([](json& d) { d["fl_x"] = -1; }), {"\"fl_x\" must be positive"}},
      {"angle out of range",
       edited([](json& d) {
         d.erase("fl_x");
         d["camera_angle_x"] = 4;
       }),
       {"\"camera_angle_x\" must be a field of view in (0, pi)"}},
      {"fractional width",
       edited([](json& d) { d["w"] = 8.5; }),
       {"\"w\" must be an integer image size"}},
      {"huge height",
       edited([](json& d) { d["frames"][1]["h"] = 1e9; }),
       {"frame 1: \"h\" must be an integer image size"}},
      {"equirectangular",
       edited([](json& d) { d["camera_model"] = "EQUIRECTANGULAR"; }),
       {"unsupported \"camera_model\" \"EQUIRECTANGULAR\""}},
      {"instant-ngp fisheye",
       edited([](json& d) {
         d["k1"] = 0.05;
         d["is_fisheye"] = true;
       }),
       {"\"is_fisheye\": true) are not supported"}},
      {"model not string",
       edited([](json& d) { d["frames"][0]["camera_model"] = 1; }),
       {"frame 0: \"camera_model\" must be a string"}},
      {"k4", edited([](json& d) { d["k4"] = 0.01; }), {"\"k4\" is not supported"}},
      {"focal beyond float",
       edited([](json& d) { d["fl_x"] = 1e300; }),
       {"\"fl_x\" 1e+300 is beyond the single-precision range"}},
      {"coefficient beyond float",
       edited([](json& d) { d["frames"][1]["p1"] = -1e308; }),
       {"frame 1: \"p1\" -1e+308 is beyond the single-precision range"}},
      {"angle for a focal beyond float",
       edited([](json& d) {
         d.erase("fl_x");
         d["camera_angle_x"] = 1e-300;
       }),
       {"\"camera_angle_x\" is too small, got 1e-300"}},
  };
  for (const BadInput& bad : cases) {
    SCOPED_TRACE(bad.what);
    TempDir dir;
    const fs::path json_path = dir / "transforms.json";
    write_text(json_path, bad.text());
    const std::string message = error_message([&] { read_nerfstudio_scene(json_path, {}); });
    EXPECT_EQ(message.rfind(json_path.string() + ": ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    for (const std::string& piece : bad.expected)
      EXPECT_NE(message.find(piece), std::string::npos) << message;
  }
}

TEST(BlenderScene, BadInputNamesFileAndKey) {
  TempDir dir;
  const fs::path json_path = dir / "transforms_train.json";
  write_text(json_path, json{{"frames", {frame("r_0")}}}.dump());
  std::string message = error_message([&] { read_blender_scene(dir.path(), {}); });
  EXPECT_EQ(message, json_path.string() + ": missing \"camera_angle_x\"");

  write_text(json_path, json{{"camera_angle_x", "wide"}, {"frames", {frame("r_0")}}}.dump());
  message = error_message([&] { read_blender_scene(dir.path(), {}); });
  EXPECT_EQ(message, json_path.string() + ": \"camera_angle_x\" must be a number");
}

}  // namespace
}  // namespace iesrgs
