#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "synth/camera_path.hpp"
#include "synth/geometry.hpp"

namespace iesrgs::synth {
namespace {

Vec3 column(const Mat3& m, int c) {
  return {m(0, c), m(1, c), m(2, c)};
}

double elevation_degrees(const CameraPose& pose) {
  return std::asin(pose.position.z / pose.position.norm()) * 180 / kPi;
}

TEST(SynthCameraPath, LookAtFacesTheTargetUpright) {
  const Vec3 eye{3, -2, 1.5}, target{0.2, 0.1, -0.3};
  const CameraPose pose = look_at(eye, target);
  const Vec3 right = column(pose.axes, 0), up = column(pose.axes, 1), back = column(pose.axes, 2);
  const Vec3 forward = normalized(target - eye);
  EXPECT_NEAR(back.dot(forward), -1, 1e-12);
  EXPECT_NEAR(right.norm(), 1, 1e-12);
  EXPECT_NEAR(up.norm(), 1, 1e-12);
  EXPECT_NEAR(right.dot(up), 0, 1e-12);
  const Vec3 handedness = right.cross(up) - back;
  EXPECT_NEAR(handedness.norm(), 0, 1e-12);
  EXPECT_NEAR(right.z, 0, 1e-12);  // horizon level
  EXPECT_GT(up.z, 0);              // world up is image up
}

TEST(SynthCameraPath, MatrixIsCameraToWorldWithTheLastRowOfAnAffineMap) {
  const CameraPose pose = look_at({1, 2, 3}, {0, 0, 0});
  const auto m = pose.matrix();
  EXPECT_EQ(m[3], (std::array<double, 4>{0, 0, 0, 1}));
  for (int r = 0; r < 3; ++r) {
    EXPECT_EQ(m[r][3], pose.position[r]);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(m[r][c], pose.axes(r, c));
  }
}

TEST(SynthCameraPath, TrainingViewsCoverTheUpperHemisphere) {
  const auto poses = train_orbit(100, 3);
  ASSERT_EQ(poses.size(), 100u);
  double lowest = 90, highest = 0, mean_x = 0, mean_y = 0;
  for (const CameraPose& pose : poses) {
    EXPECT_NEAR(pose.position.norm(), kOrbitRadius, 1e-12);
    lowest = std::min(lowest, elevation_degrees(pose));
    highest = std::max(highest, elevation_degrees(pose));
    mean_x += pose.position.x / 100;
    mean_y += pose.position.y / 100;
  }
  EXPECT_GE(lowest, 5 - 1e-9);
  EXPECT_LT(lowest, 8);
  EXPECT_LE(highest, 85 + 1e-9);
  EXPECT_GT(highest, 75);
  EXPECT_LT(std::hypot(mean_x, mean_y), 0.3);  // all around, not bunched on one side
}

TEST(SynthCameraPath, TrainingViewsDependOnTheSeedOnly) {
  const auto a = train_orbit(10, 5), same = train_orbit(10, 5), other = train_orbit(10, 6);
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(a[i].position.x, same[i].position.x);
    EXPECT_EQ(a[i].position.z, same[i].position.z);
    EXPECT_GT((a[i].position - other[i].position).norm(), 1e-6);
  }
}

TEST(SynthCameraPath, TestViewsAreASpiralApartFromTheTrainingViews) {
  const auto test = test_orbit(50);
  const auto train = train_orbit(100, 0);
  ASSERT_EQ(test.size(), 50u);
  EXPECT_NEAR(elevation_degrees(test.front()), 15, 1e-9);
  EXPECT_NEAR(elevation_degrees(test.back()), 45, 1e-9);
  for (const CameraPose& view : test) {
    EXPECT_NEAR(view.position.norm(), kOrbitRadius, 1e-12);
    for (const CameraPose& seen : train) EXPECT_GT((view.position - seen.position).norm(), 1e-3);
  }
  EXPECT_EQ(test_orbit(1).size(), 1u);
  EXPECT_TRUE(test_orbit(0).empty());
}

}  // namespace
}  // namespace iesrgs::synth
