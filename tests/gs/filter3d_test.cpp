#include "gs/filter3d.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"

namespace iesrgs::gs {
namespace {

// Camera at `center` looking down +z (identity rotation), 100x80 pixels.
Camera camera_at(const Vec3& center, double focal) {
  Camera c;
  c.intrinsics = {100, 80, focal, focal, 50, 40};
  c.translation = -center;
  return c;
}

TEST(Filter3d, NearestSeeingCameraAndLargestFocal) {
  const std::vector<Camera> cameras = {camera_at({0, 0, 0}, 100), camera_at({0, 0, -3}, 150)};
  const float means[] = {
      0.1f, 0.f, 2.f,   // seen by both: nearest z is 2
      1.2f, 0.f, 2.f,   // u = 100 * 0.6 + 50 = 110 for the first: inside the 15% margin
      3.0f, 0.f, 2.f,   // outside both frames
      0.f,  0.f, -1.f,  // behind the first camera, z = 2 for the second
      0.f,  0.f, 5.f,   // nearest z is 5: the largest distance seen
      0.f,  0.f, 0.1f,  // inside the first camera's near plane (z <= 0.2): z = 3.1 for the second
  };
  const std::vector<float> s = filter3d_std(means, 6, cameras);
  const double k = std::sqrt(0.2) / 150;  // largest focal
  ASSERT_EQ(s.size(), 6u);
  EXPECT_NEAR(s[0], 2 * k, 1e-7);
  EXPECT_NEAR(s[1], 2 * k, 1e-7);
  EXPECT_NEAR(s[2], 5 * k, 1e-7);  // unseen: the largest distance seen
  EXPECT_NEAR(s[3], 2 * k, 1e-7);
  EXPECT_NEAR(s[4], 5 * k, 1e-7);
  EXPECT_NEAR(s[5], 3.1 * k, 1e-7);
}

TEST(Filter3d, FrameMarginIsFifteenPercent) {
  const std::vector<Camera> cameras = {camera_at({0, 0, 0}, 100), camera_at({0, 0, -10}, 100)};
  // u = 100 x / 1 + 50: x = 0.64 -> 114 (inside), x = 0.66 -> 116 (outside, only the far camera).
  const float means[] = {0.64f, 0.f, 1.f, 0.66f, 0.f, 1.f};
  const std::vector<float> s = filter3d_std(means, 2, cameras);
  const double k = std::sqrt(0.2) / 100;
  EXPECT_NEAR(s[0], 1 * k, 1e-7);
  EXPECT_NEAR(s[1], 11 * k, 1e-6);
}

TEST(Filter3d, VerticalMarginTakesFyAndTheHeight) {
  Camera near = camera_at({0, 0, 0}, 100);
  near.intrinsics.fy = 50;
  const std::vector<Camera> cameras = {near, camera_at({0, 0, -10}, 100)};
  // v = 50 y / 1 + 40 against the bound 1.15 x 80 = 92: y = 1.0 -> 90 (inside), y = 1.1 -> 95
  // (outside, though inside the width's bound, 115). With fx for fy, y = 1.0 would land at 140.
  const float means[] = {0.f, 1.0f, 1.f, 0.f, 1.1f, 1.f};
  const std::vector<float> s = filter3d_std(means, 2, cameras);
  const double k = std::sqrt(0.2) / 100;
  EXPECT_NEAR(s[0], 1 * k, 1e-7);
  EXPECT_NEAR(s[1], 11 * k, 1e-6);
}

TEST(Filter3d, NeedsCameras) {
  EXPECT_THROW(filter3d_std(nullptr, 0, {}), Error);
}

}  // namespace
}  // namespace iesrgs::gs
