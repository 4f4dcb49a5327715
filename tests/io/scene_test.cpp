#include "io/scene.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include <nlohmann/json.hpp>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "support/expect_error.hpp"
#include "support/looking_cameras.hpp"
#include "support/temp_dir.hpp"
#include "synth/dataset_writer.hpp"

namespace iesrgs {
namespace {

using testing::contains;
using testing::error_message;
using testing::TempDir;

TEST(Scene, NormalizationAsGaussianSplatting) {
  Scene scene;
  for (double x : {-2.0, 0.0, 4.0}) {
    Camera camera;
    camera.translation = {-x, 0, 0};  // identity rotation: center = (x, 0, 0)
    scene.cameras.push_back(camera);
  }
  scene.cameras.back().split = Split::Test;  // test cameras do not count
  const SceneNormalization norm = scene.normalization();
  EXPECT_NEAR(norm.center.x, -1, 1e-12);
  EXPECT_NEAR(norm.radius, 1.1, 1e-12);
}

// As 3DGS trains them: NeRF Synthetic over white, captures over black, unless told otherwise.
TEST(Scene, TheDefaultBackgroundIsWhiteForNerfSyntheticAndBlackForCaptures) {
  TempDir dir;
  synth::write_synth_dataset(dir / "blender", {synth::SynthFormat::Blender, 8, 2, 1});
  synth::write_synth_dataset(dir / "colmap", {synth::SynthFormat::Colmap, 8, 3, 0});
  const std::array<float, 3> white{1, 1, 1}, black{0, 0, 0}, blue{0, 0, 1};
  EXPECT_EQ(load_scene(dir / "blender").background, white);
  const Scene capture = load_scene(dir / "colmap");
  EXPECT_EQ(capture.background, black);
  // The synthetic capture's photos show that background where the object is not.
  const Image8 photo = read_image8(capture.cameras.front().image_path);
  EXPECT_EQ(photo.at(0, 0, 0) + photo.at(0, 0, 1) + photo.at(0, 0, 2), 0);
  SceneOptions options;
  options.background = blue;
  EXPECT_EQ(load_scene(dir / "blender", options).background, blue);
  EXPECT_EQ(load_scene(dir / "colmap", options).background, blue);
}

TEST(Scene, TwoViewsOfASplitWithOneNameAreRefused) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 3, 1});
  const auto json_path = dir / "scene" / "transforms_train.json";
  nlohmann::json transforms = nlohmann::json::parse(read_file(json_path));
  std::filesystem::create_directories(dir / "scene" / "other");
  std::filesystem::copy_file(dir / "scene" / "test" / "r_0.png",
                             dir / "scene" / "other" / "r_0.png");
  transforms["frames"][1]["file_path"] = "./other/r_0";  // a second train view named r_0
  write_file_atomically(json_path, transforms.dump());
  const std::string message = error_message([&] { load_scene(dir / "scene"); });
  EXPECT_TRUE(contains(message, "train views named 'r_0'")) << message;
  EXPECT_TRUE(contains(message, "other/r_0.png")) << message;
}

// One image under two cameras, however its path is spelled: a test image among the training
// views, or one photo given two poses.
TEST(Scene, AnImagePosedTwiceIsRefused) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 3, 1});
  const auto json_path = dir / "scene" / "transforms_train.json";
  const nlohmann::json original = nlohmann::json::parse(read_file(json_path));
  for (const auto& [path, views] :
       {std::pair{"./test/r_0", "train view 'r_0' and test view 'r_0'"},
        std::pair{"train/../train/r_0.png", "train view 'r_0' and train view 'r_0'"}}) {
    nlohmann::json transforms = original;
    transforms["frames"][1]["file_path"] = path;
    write_file_atomically(json_path, transforms.dump());
    const std::string message = error_message([&] { load_scene(dir / "scene"); });
    EXPECT_TRUE(contains(message, std::string("is posed twice, as ") + views)) << message;
  }
  // Data stores link identical images of distinct frames to one file: those are two images.
  nlohmann::json linked = original;
  std::filesystem::create_symlink(dir / "scene" / "train" / "r_0.png", dir / "scene" / "copy.png");
  linked["frames"][1]["file_path"] = "copy.png";
  write_file_atomically(json_path, linked.dump());
  EXPECT_EQ(load_scene(dir / "scene").cameras.size(), 4u);
}

// Read as a nerfstudio file, a split file would give a split of its own views.
TEST(Scene, ASplitFileOfANerfSyntheticSceneNamesItsFolder) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 3, 1});
  for (const char* file : {"transforms_train.json", "transforms_test.json"}) {
    const std::string message = error_message([&] { load_scene(dir / "scene" / file); });
    EXPECT_TRUE(contains(message, std::string(file) +
                                      ": one split of a NeRF Synthetic scene: give the scene's "
                                      "folder, " +
                                      (dir / "scene").string()))
        << message;
  }
}

// Alone in a folder, a split file is still not a nerfstudio scene.
TEST(Scene, ASplitFileWithoutItsSceneIsRefused) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 3, 1});
  std::filesystem::create_directories(dir / "alone");
  std::filesystem::copy_file(dir / "scene" / "transforms_test.json",
                             dir / "alone" / "transforms_val.json");
  const std::string message =
      error_message([&] { load_scene(dir / "alone" / "transforms_val.json"); });
  EXPECT_TRUE(contains(message,
                       "transforms_val.json: one split of a NeRF Synthetic scene, which "
                       "is read from its folder's transforms_train.json and "
                       "transforms_test.json; this folder holds neither"))
      << message;
}

// Renders into the scene's folder would replace a nerfstudio scene's rgb/ images, a trained
// model its SfM points.
TEST(Scene, OutputsGoAnywhereButTheScenesOwnFolder) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 3, 1});
  const Scene scene = load_scene(dir / "scene");
  EXPECT_EQ(
      error_message([&] { refuse_output_in_scene_folder(dir / "x" / ".." / "scene", scene); }),
      (dir / "x" / ".." / "scene").string() +
          ": is the scene's own folder, whose files the outputs could replace; write them "
          "elsewhere (a folder inside it will do)");
  refuse_output_in_scene_folder(dir / "scene" / "renders", scene);
  refuse_output_in_scene_folder(dir / "renders", scene);
}

TEST(Scene, ViewsOfDifferentSplitsMayShareAName) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 2, 2});
  const Scene scene = load_scene(dir / "scene");
  EXPECT_EQ(scene.split(Split::Train)[0]->name, scene.split(Split::Test)[0]->name);
  require_training_views(scene);
}

TEST(Scene, ASceneWithoutTrainingViewsNamesItself) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Colmap, 8, 3, 0});
  SceneOptions every_view_held_out;
  every_view_held_out.test_every = 1;
  const Scene scene = load_scene(dir / "scene", every_view_held_out);
  const std::string message = error_message([&] { require_training_views(scene); });
  EXPECT_TRUE(contains(message, "no training views: all 3 images are test views")) << message;
  EXPECT_TRUE(contains(message, (dir / "scene").string())) << message;
}

TEST(Scene, TrainingViewsFromOnePositionAreRefused) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 1, 1});
  const Scene one_view = load_scene(dir / "scene");
  require_training_views(one_view);  // enough to render from, as bench raster does
  const std::string message = error_message([&] { require_trainable_views(one_view); });
  EXPECT_TRUE(contains(message, "a single training view, at (")) << message;
  EXPECT_TRUE(contains(message, (dir / "scene").string())) << message;

  // A camera turning in place: three directions, one center.
  Scene turning;
  for (double turn : {0.0, 1.0, 2.0}) {
    Camera camera;
    camera.rotation = quat_to_rotation(std::cos(turn / 2), 0, std::sin(turn / 2), 0);
    camera.translation = -(camera.rotation * Vec3{1, 2, 3});
    turning.cameras.push_back(camera);
  }
  EXPECT_TRUE(contains(error_message([&] { require_trainable_views(turning); }),
                       "all 3 training views at one position, (1, 2, 3)"));
}

// Cameras on a small patch facing SfM points `depth` away.
Scene cameras_facing_points(double spread, double depth) {
  Scene scene;
  for (double x : {-spread, 0.0, spread}) {
    Camera camera;
    camera.translation = {-x, 0, 0};  // identity rotation: center (x, 0, 0), looking along +z
    scene.cameras.push_back(camera);
  }
  for (double y : {-1.0, 1.0}) scene.points.positions.push_back({0, y, depth});
  return scene;
}

TEST(Scene, CamerasNearlyAtOnePositionAreWarnedAbout) {
  const std::vector<std::string> warnings = camera_warnings(cameras_facing_points(0.05, 10));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(
      contains(warnings[0], "the 3 training cameras lie within 0.05 of their center, 0.5 %"))
      << warnings[0];
  require_trainable_views(cameras_facing_points(0.05, 10));  // warned about, not refused
  // A forward-facing capture spreads over a few percent of its depth.
  EXPECT_TRUE(camera_warnings(cameras_facing_points(0.5, 10)).empty());
}

TEST(Scene, CamerasAroundAnObjectAreNotWarnedAbout) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 4, 1});
  EXPECT_TRUE(camera_warnings(load_scene(dir / "scene")).empty());
}

// Poses in OpenCV's convention read as OpenGL's turn every camera around: what they look at lies
// behind them, and training would learn nothing.
TEST(Scene, CamerasFacingAwayAreWarnedAbout) {
  const std::vector<std::string> behind = camera_warnings(cameras_facing_points(0.5, -10));
  ASSERT_EQ(behind.size(), 1u);
  EXPECT_TRUE(contains(behind[0], "3 of the 3 training cameras face away from the scene's points"))
      << behind[0];

  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 4, 1});
  const auto json_path = dir / "scene" / "transforms_train.json";
  nlohmann::json transforms = nlohmann::json::parse(read_file(json_path));
  for (nlohmann::json& frame : transforms["frames"])
    for (int row = 0; row < 3; ++row)
      for (int column : {1, 2})  // y and z axes negated: OpenCV's convention
        frame["transform_matrix"][row][column] =
            -frame["transform_matrix"][row][column].get<double>();
  write_file_atomically(json_path, transforms.dump());
  const std::vector<std::string> turned = camera_warnings(load_scene(dir / "scene"));
  ASSERT_EQ(turned.size(), 1u);
  EXPECT_TRUE(contains(turned[0],
                       "4 of the 4 training cameras face away from the point their "
                       "optical axes meet: their views would show none of it"))
      << turned[0];
  EXPECT_TRUE(contains(turned[0], "one written with OpenCV's, z forward")) << turned[0];

  // Turned around on a narrow arc (24 degrees of it), with no points: their axes still meet.
  Scene arc;
  for (int k = -2; k <= 2; ++k) {
    const double angle = k * 6 * kPi / 180;
    const Vec3 eye{4 * std::sin(angle), -4 * std::cos(angle), 0};
    arc.cameras.push_back(testing::camera_at(eye, eye * 2.0));
  }
  const std::vector<std::string> narrow = camera_warnings(arc);
  ASSERT_EQ(narrow.size(), 1u);
  EXPECT_TRUE(contains(narrow[0],
                       "5 of the 5 training cameras face away from the point their "
                       "optical axes meet"))
      << narrow[0];
}

// A forward-facing capture's nearly parallel axes may meet behind it, and a camera inside the
// scene sees half its points: neither faces away.
TEST(Scene, ForwardFacingAndInsideOutCapturesAreNotWarnedAbout) {
  for (const double tilt : {-0.035, 0.035}) {  // 2 degrees, outward or inward
    Scene forward;
    for (double x = -2; x <= 2; ++x)
      for (double y = -1; y <= 1; ++y) {
        Camera camera;
        camera.rotation = quat_to_rotation(std::cos(tilt * x / 2), 0, std::sin(tilt * x / 2), 0);
        camera.translation = -(camera.rotation * Vec3{x, y, 0});
        forward.cameras.push_back(camera);
      }
    const std::vector<std::string> warnings = camera_warnings(forward);
    EXPECT_TRUE(warnings.empty()) << tilt << ": " << warnings.front();
  }
  Scene inside_out;
  for (int k = 0; k < 8; ++k) {
    const double turn = k * kPi / 4;  // about y: looking out along the ring
    Camera camera;
    camera.rotation = quat_to_rotation(std::cos(turn / 2), 0, std::sin(turn / 2), 0);
    camera.translation = -(camera.rotation * Vec3{std::sin(turn), 0, std::cos(turn)});
    inside_out.cameras.push_back(camera);
    for (int j = 0; j < 16; ++j)
      inside_out.points.positions.push_back(
          {10 * std::cos(j * kPi / 8), 0.5 * (j % 3), 10 * std::sin(j * kPi / 8)});
  }
  const std::vector<std::string> warnings = camera_warnings(inside_out);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
}

TEST(Scene, AFieldOfViewOf180DegreesIsRefused) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 2, 1});
  const auto json_path = dir / "scene" / "transforms_train.json";
  nlohmann::json transforms = nlohmann::json::parse(read_file(json_path));
  transforms["camera_angle_x"] = 3.1415;  // radians: a focal length of 0.0002 pixels
  write_file_atomically(json_path, transforms.dump());
  const std::string message = error_message([&] { load_scene(dir / "scene"); });
  EXPECT_TRUE(contains(message,
                       "make a field of view of 180 degrees: a pinhole camera sees less "
                       "than 179"))
      << message;
  EXPECT_TRUE(contains(message, "r_0.png")) << message;
}

// cx of a million pixels for an 8-pixel image: a view that shows the model nowhere.
TEST(Scene, APrincipalPointFarOutsideTheImageIsRefused) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 2, 1});
  const nlohmann::json blender =
      nlohmann::json::parse(read_file(dir / "scene" / "transforms_train.json"));
  nlohmann::json capture = {{"fl_x", 8}, {"fl_y", 8}, {"cx", 1e6}, {"cy", 4}, {"w", 8}, {"h", 8}};
  for (nlohmann::json frame : blender["frames"]) {
    frame["file_path"] = "scene/" + frame["file_path"].get<std::string>();
    capture["frames"].push_back(frame);
  }
  write_file_atomically(dir / "transforms.json", capture.dump());
  const std::string message = error_message([&] { load_scene(dir / "transforms.json"); });
  EXPECT_TRUE(contains(message, "principal point 1e+06, 4 for a 8x8 image")) << message;
  EXPECT_TRUE(contains(message, "the principal point lies more than the image's own size outside"))
      << message;
  capture["cx"] = -7.5;  // off-centre, but a lens could be so
  write_file_atomically(dir / "transforms.json", capture.dump());
  EXPECT_EQ(load_scene(dir / "transforms.json").cameras.size(), 2u);
}

TEST(Scene, ADownscaleThatLeavesNoPixelIsRefused) {
  TempDir dir;
  synth::write_synth_dataset(dir / "scene", {synth::SynthFormat::Blender, 8, 2, 1});
  SceneOptions options;
  options.downscale = 16;  // 8 / 16 rounds to 1 pixel: small, but a view
  EXPECT_EQ(load_scene(dir / "scene", options).cameras.front().intrinsics.width, 1);
  options.downscale = 17;
  const std::string message = error_message([&] { load_scene(dir / "scene", options); });
  EXPECT_TRUE(contains(message, "at 1/17 of its 8x8 pixels, this view would have none")) << message;
  EXPECT_TRUE(contains(message, ".png")) << message;
}

}  // namespace
}  // namespace iesrgs
