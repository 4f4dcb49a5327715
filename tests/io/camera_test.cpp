#include <gtest/gtest.h>

#include <cmath>

#include "io/camera.hpp"
#include "support/looking_cameras.hpp"
#include "support/projection.hpp"

namespace iesrgs {
namespace {

using testing::camera_at;
using testing::pointers;
using testing::project;

TEST(Camera, OpenGlCameraToWorldBecomesOpenCvWorldToCamera) {
  // An OpenGL camera at (0, 0, 4) looking down -z at the origin, y up.
  const double c2w[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 4}, {0, 0, 0, 1}};
  Camera camera;
  opengl_c2w_to_opencv_w2c(c2w, camera.rotation, camera.translation);
  camera.intrinsics = {100, 80, 50, 50, 50, 40};
  EXPECT_NEAR(camera.center().z, 4, 1e-12);
  const Vec3 origin_in_camera = camera.rotation * Vec3{} + camera.translation;
  EXPECT_NEAR(origin_in_camera.z, 4, 1e-12);  // in front: OpenCV z forward
  auto [u, v] = project(camera, {0, 0, 0});
  EXPECT_NEAR(u, 50, 1e-9);
  EXPECT_NEAR(v, 40, 1e-9);
  // World +y is up for OpenGL, so it lands in the upper half of the image (smaller v).
  std::tie(u, v) = project(camera, {0, 1, 0});
  EXPECT_LT(v, 40);
  std::tie(u, v) = project(camera, {1, 0, 0});
  EXPECT_GT(u, 50);
}

TEST(Camera, ScalingKeepsTheFieldOfView) {
  const Intrinsics k{200, 100, 180, 170, 100, 50};
  const Intrinsics hr = k.scaled(4);
  EXPECT_EQ(hr.width, 800);
  EXPECT_EQ(hr.height, 400);
  EXPECT_DOUBLE_EQ(hr.fx, 720);
  EXPECT_DOUBLE_EQ(hr.cx, 400);
  EXPECT_NEAR(hr.fov_x(), k.fov_x(), 1e-12);
  EXPECT_NEAR(hr.fov_y(), k.fov_y(), 1e-12);
  // A world point lands on the same relative image position at both resolutions.
  Camera lr;
  lr.intrinsics = k;
  lr.translation = {0.1, -0.2, 3};
  const Camera high = lr.scaled(4);
  const auto [u, v] = project(lr, {0.3, 0.2, 0.5});
  const auto [U, V] = project(high, {0.3, 0.2, 0.5});
  EXPECT_NEAR(U, 4 * u, 1e-9);
  EXPECT_NEAR(V, 4 * v, 1e-9);
}

TEST(Camera, DistortionModelMatchesOpenCv) {
  const Distortion d{0.1, -0.05, 0.001, -0.002};
  double xd, yd;
  d.apply(0.3, -0.2, xd, yd);
  const double r2 = 0.13, radial = 1 + 0.1 * r2 - 0.05 * r2 * r2;
  EXPECT_NEAR(xd, 0.3 * radial + 2 * 0.001 * 0.3 * -0.2 + -0.002 * (r2 + 2 * 0.09), 1e-15);
  EXPECT_NEAR(yd, -0.2 * radial + 0.001 * (r2 + 2 * 0.04) + 2 * -0.002 * 0.3 * -0.2, 1e-15);
  EXPECT_FALSE(Distortion{}.any());
}

// OpenCV's fisheye: a ray at 45 degrees (x = 1 on the normalized plane) is imaged at radius
// theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8), theta = pi / 4.
TEST(Camera, FisheyeModelMatchesOpenCv) {
  const double theta = std::atan(1.0), t2 = theta * theta;
  double xd, yd;
  Distortion equidistant;
  equidistant.fisheye = true;
  EXPECT_TRUE(equidistant.any());
  equidistant.apply(1, 0, xd, yd);
  EXPECT_NEAR(xd, theta, 1e-15);
  EXPECT_EQ(yd, 0);
  const Distortion d{0.1, -0.05, 0, 0, 0.02, -0.01, 0, 0, true};
  d.apply(0.6, 0.8, xd, yd);  // r = 1: the same ray, turned
  const double imaged =
      theta * (1 + 0.1 * t2 - 0.05 * t2 * t2 + 0.02 * t2 * t2 * t2 - 0.01 * t2 * t2 * t2 * t2);
  EXPECT_NEAR(xd, 0.6 * imaged, 1e-15);
  EXPECT_NEAR(yd, 0.8 * imaged, 1e-15);
}

TEST(Camera, FocusPointIsWhereTheOpticalAxesMeet) {
  const Vec3 target{0.3, -0.2, 0.5};
  const std::vector<Camera> cameras = testing::ring(3, 2, 0.4, 1.5, target, 7);
  const std::optional<Vec3> focus = focus_point(pointers(cameras));
  ASSERT_TRUE(focus.has_value());
  EXPECT_NEAR((*focus - target).norm(), 0, 1e-9);
}

TEST(Camera, ParallelCamerasHaveNoFocusPoint) {
  const std::vector<Camera> cameras = {camera_at({0, 0, 0}, {0, 5, 0}),
                                       camera_at({1, 0, 0}, {1, 5, 0})};
  EXPECT_FALSE(focus_point(pointers(cameras)).has_value());
}

}  // namespace
}  // namespace iesrgs
