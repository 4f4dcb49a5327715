#include "pipeline/camera_path.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "support/expect_error.hpp"
#include "support/looking_cameras.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::camera_at;
using testing::pointers;
using testing::ring;

TEST(CameraPath, CircleOfCamerasGivesThatCircleLookingAtItsCentre) {
  const Vec3 target{1, 2, 0};
  const std::vector<Camera> cameras = ring(3, 3, 0, 1, target, 8);
  const std::vector<Camera> path = orbit_path(pointers(cameras), 12);
  ASSERT_EQ(path.size(), 12u);
  EXPECT_EQ(path[0].name, "path_0000");
  EXPECT_EQ(path[11].name, "path_0011");
  for (const Camera& camera : path) {
    const Vec3 offset = camera.center() - target;
    EXPECT_NEAR(std::hypot(offset.x, offset.y), 3, 1e-9);
    EXPECT_NEAR(offset.z, 1, 1e-9);
    // The target sits on the optical axis in front of the camera, world up is image up.
    const Vec3 seen = camera.rotation * target + camera.translation;
    EXPECT_NEAR(seen.x, 0, 1e-9);
    EXPECT_NEAR(seen.y, 0, 1e-9);
    EXPECT_GT(seen.z, 0);
    EXPECT_LT(camera.rotation(1, 2), 0);  // the camera's down axis points down the world's z
    EXPECT_EQ(camera.intrinsics.width, 64);
    EXPECT_EQ(camera.intrinsics.fx, 50);
  }
}

TEST(CameraPath, EllipseOfCamerasKeepsItsAxesAndOrientation) {
  const double angle = 0.5;
  const std::vector<Camera> cameras = ring(4, 2, angle, 0.5, {0, 0, 0}, 16);
  const std::vector<Camera> path = orbit_path(pointers(cameras), 64);
  double longest = 0, shortest = 1e9, longest_direction = 0;
  for (const Camera& camera : path) {
    const Vec3 c = camera.center();
    const double r = std::hypot(c.x, c.y);
    if (r > longest) longest = r, longest_direction = std::atan2(c.y, c.x);
    shortest = std::min(shortest, r);
    EXPECT_NEAR(c.z, 0.5, 1e-9);
  }
  EXPECT_NEAR(longest, 4, 1e-6);
  EXPECT_NEAR(shortest, 2, 1e-6);
  EXPECT_NEAR(std::remainder(longest_direction - angle, kPi), 0, 1e-6);
}

TEST(CameraPath, ArcOfCamerasGivesASweepAlongItAndBack) {
  // Seven cameras over 120 degrees of a circle of radius 2, 0.8 above the target.
  std::vector<Camera> cameras;
  for (int i = 0; i < 7; ++i) {
    const double t = (20.0 * i - 30) * kPi / 180;
    cameras.push_back(camera_at({2 * std::cos(t), 2 * std::sin(t), 0.8}, {0, 0, 0}));
  }
  const std::vector<Camera> path = orbit_path(pointers(cameras), 20);
  double lowest = kPi, highest = -kPi;
  for (const Camera& camera : path) {
    const Vec3 c = camera.center();
    EXPECT_NEAR(std::hypot(c.x, c.y), 2, 1e-9);
    EXPECT_NEAR(c.z, 0.8, 1e-9);
    lowest = std::min(lowest, std::atan2(c.y, c.x));
    highest = std::max(highest, std::atan2(c.y, c.x));
  }
  EXPECT_NEAR(lowest * 180 / kPi, -30, 1e-6);  // from one end of the arc
  EXPECT_NEAR(highest * 180 / kPi, 90, 1e-6);  // to the other, at the middle frame
  EXPECT_NEAR((path[1].center() - path[19].center()).norm(), 0, 1e-9);  // and back
}

// `camera` turned by `angle` about its optical axis, staying where it is.
Camera rolled(Camera camera, double angle) {
  Mat3 roll = quat_to_rotation(std::cos(angle / 2), 0, 0, std::sin(angle / 2));
  camera.rotation = roll * camera.rotation;
  camera.translation = roll * camera.translation;
  return camera;
}

TEST(CameraPath, NarrowArcOfRolledCamerasKeepsTheWorldUp) {
  // Nine cameras over 8 degrees, looking 10 degrees down at the target, each rolled by up to
  // 4 degrees: the right axes alone cannot tell up from forward (they made it 51 degrees off).
  std::vector<Camera> cameras;
  for (int i = 0; i < 9; ++i) {
    const double t = (i - 4.0) * kPi / 180, height = 3 * std::tan(10 * kPi / 180);
    const double roll = 4 * std::cos(0.7 * i * i) * kPi / 180;
    cameras.push_back(rolled(camera_at({3 * std::cos(t), 3 * std::sin(t), height}, {}), roll));
  }
  for (const Camera& camera : orbit_path(pointers(cameras), 8)) {
    const Vec3 down{camera.rotation(1, 0), camera.rotation(1, 1), camera.rotation(1, 2)};
    EXPECT_LT(std::acos(-down.z) * 180 / kPi, 12) << camera.name;  // level, but for the look down
  }
}

TEST(CameraPath, CamerasAtTheirFocusPointAreAClearError) {
  std::vector<Camera> panorama;
  for (double turn : {0.0, 2.0, 4.0})
    panorama.push_back(camera_at({1, 2, 3}, {1 + std::cos(turn), 2 + std::sin(turn), 3}));
  const std::string message = testing::error_message([&] { orbit_path(pointers(panorama), 4); });
  EXPECT_TRUE(testing::contains(message, "stand at the point they look around, (1, 2, 3)"))
      << message;
}

TEST(CameraPath, ParallelCamerasAreAClearError) {
  const std::vector<Camera> cameras = {camera_at({0, 0, 0}, {0, 5, 0}),
                                       camera_at({1, 0, 0}, {1, 5, 0})};
  const std::string message = testing::error_message([&] { orbit_path(pointers(cameras), 10); });
  EXPECT_TRUE(testing::contains(message, "look in parallel directions")) << message;
}

TEST(CameraPath, InterpolatedPathPassesThroughEveryCameraInOrder) {
  const std::vector<Camera> cameras = {camera_at({3, 0, 1}, {0, 0, 0}),
                                       camera_at({0, 3, 1.5}, {0, 0, 0}),
                                       camera_at({-3, 0, 1}, {0, 0, 0})};
  const std::vector<Camera> path = interpolated_path(pointers(cameras), 5);  // 2 frames per gap
  ASSERT_EQ(path.size(), 5u);
  for (int key = 0; key < 3; ++key) {
    const Camera& frame = path[2 * key];
    EXPECT_NEAR((frame.center() - cameras[key].center()).norm(), 0, 1e-9) << key;
    for (int k = 0; k < 9; ++k)
      EXPECT_NEAR(frame.rotation.m[k], cameras[key].rotation.m[k], 1e-9) << key;
  }
  EXPECT_EQ(path[4].name, "path_0004");
}

TEST(CameraPath, InterpolatedPathSlerpsHalfwayBetweenTwoCameras) {
  // Two cameras 90 degrees apart around the target: halfway looks from 45 degrees.
  const std::vector<Camera> cameras = {camera_at({2, 0, 0}, {0, 0, 0}),
                                       camera_at({4, 2, 0}, {4, 0, 0})};
  const Camera middle = interpolated_path(pointers(cameras), 3)[1];
  EXPECT_NEAR((middle.center() - Vec3{3, 1, 0}).norm(), 0, 1e-9);  // straight between two keys
  const Vec3 forward{middle.rotation(2, 0), middle.rotation(2, 1), middle.rotation(2, 2)};
  EXPECT_NEAR(forward.dot(normalized(Vec3{-1, -1, 0})), 1, 1e-9);
}

TEST(CameraPath, InterpolatedPathOfOneCameraStaysOnIt) {
  const std::vector<Camera> cameras = {camera_at({1, 2, 3}, {0, 0, 0})};
  for (const Camera& frame : interpolated_path(pointers(cameras), 4))
    EXPECT_NEAR((frame.center() - cameras[0].center()).norm(), 0, 1e-9);
}

}  // namespace
}  // namespace iesrgs::pipeline
