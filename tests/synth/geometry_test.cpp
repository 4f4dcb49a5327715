#include <gtest/gtest.h>

#include <cmath>

#include "synth/geometry.hpp"

namespace iesrgs::synth {
namespace {

void expect_near(const Vec3& actual, const Vec3& expected, double tolerance = 1e-12) {
  EXPECT_NEAR(actual.x, expected.x, tolerance);
  EXPECT_NEAR(actual.y, expected.y, tolerance);
  EXPECT_NEAR(actual.z, expected.z, tolerance);
}

Ray ray(const Vec3& origin, const Vec3& direction) {
  return {origin, normalized(direction)};
}

TEST(SynthGeometry, SphereHitDistanceAndNormal) {
  const Shape sphere = Sphere{{1, 2, 3}, 0.5};
  const auto t = hit_distance(sphere, ray({1, 2, -2}, {0, 0, 1}));
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 4.5, 1e-12);
  expect_near(surface_at(sphere, {1, 2, 2.5}).normal, {0, 0, -1});

  // Off-center: the chord at distance 0.3 from the center starts 0.4 before it.
  const auto off = hit_distance(sphere, ray({1.3, 2, -2}, {0, 0, 1}));
  ASSERT_TRUE(off);
  EXPECT_NEAR(*off, 5 - 0.4, 1e-12);
  expect_near(surface_at(sphere, {1.3, 2, 2.6}).normal, {0.6, 0, -0.8});
}

TEST(SynthGeometry, SphereFromInsideHitsTheExit) {
  const auto t = hit_distance(Sphere{{0, 0, 0}, 2}, ray({0.5, 0, 0}, {1, 0, 0}));
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.5, 1e-12);
}

TEST(SynthGeometry, SphereMisses) {
  const Shape sphere = Sphere{{0, 0, 0}, 1};
  EXPECT_FALSE(hit_distance(sphere, ray({0, 0, -5}, {0, 0, -1})));     // pointing away
  EXPECT_FALSE(hit_distance(sphere, ray({1.001, 0, -5}, {0, 0, 1})));  // just beside it
  EXPECT_FALSE(hit_distance(sphere, ray({0, 0, -5}, {0.3, 0, 1})));    // passing at an angle
  EXPECT_TRUE(hit_distance(sphere, ray({0.999, 0, -5}, {0, 0, 1})));   // grazing, but inside
}

TEST(SynthGeometry, AxisAlignedBoxHitDistanceAndNormal) {
  const Shape box = Box{{1, 2, 3}, {1, 2, 3}, Mat3{}};
  const auto from_left = hit_distance(box, ray({-5, 2.5, 3.5}, {1, 0, 0}));
  ASSERT_TRUE(from_left);
  EXPECT_NEAR(*from_left, 5, 1e-12);
  expect_near(surface_at(box, {0, 2.5, 3.5}).normal, {-1, 0, 0});

  const auto from_above = hit_distance(box, ray({1.5, 2, 10}, {0, 0, -1}));
  ASSERT_TRUE(from_above);
  EXPECT_NEAR(*from_above, 4, 1e-12);
  expect_near(surface_at(box, {1.5, 2, 6}).normal, {0, 0, 1});

  // Diagonal through the corner region: enters through the face y = 0 at t = 2 * sqrt(2).
  const auto diagonal = hit_distance(box, ray({-0.5, -2, 3}, {1, 1, 0}));
  ASSERT_TRUE(diagonal);
  EXPECT_NEAR(*diagonal, 2 * std::sqrt(2.0), 1e-12);
}

TEST(SynthGeometry, BoxMisses) {
  const Shape box = Box{{0, 0, 0}, {1, 1, 1}, Mat3{}};
  EXPECT_FALSE(hit_distance(box, ray({-5, 0, 0}, {-1, 0, 0})));    // pointing away
  EXPECT_FALSE(hit_distance(box, ray({-5, 1.01, 0}, {1, 0, 0})));  // parallel, just outside
  EXPECT_FALSE(hit_distance(box, ray({-5, 0, 0}, {1, 1.2, 0})));   // passes the corner
}

TEST(SynthGeometry, RotatedBoxHitDistanceAndNormal) {
  // Turned 45 degrees about z: the face with local +y faces (-1, 1, 0) / sqrt(2).
  const Shape box = Box{{0, 0, 0}, {1, 1, 1}, rotation_z(-kPi / 4)};
  const double s = std::sqrt(2.0);
  const auto corner = hit_distance(box, ray({-5, 0, 0}, {1, 0, 0}));
  ASSERT_TRUE(corner);
  EXPECT_NEAR(*corner, 5 - s, 1e-12);

  const auto face = hit_distance(box, ray({-5, 0.3, 0}, {1, 0, 0}));
  ASSERT_TRUE(face);
  EXPECT_NEAR(*face, 5 + 0.3 - s, 1e-12);
  expect_near(surface_at(box, {0.3 - s, 0.3, 0}).normal, {-1 / s, 1 / s, 0});

  // Where the turned box has its corners cut: the same box unturned would be hit.
  const Ray vertical = ray({0.95, 0.95, 5}, {0, 0, -1});
  EXPECT_FALSE(hit_distance(box, vertical));
  EXPECT_TRUE(hit_distance(Box{{0, 0, 0}, {1, 1, 1}, Mat3{}}, vertical));
}

TEST(SynthGeometry, TextureCoordinatesAreWorldLengths) {
  // Along a box face and along a sphere's equator, moving 0.1 in the world moves 0.1 in (u, v).
  const Shape box = Box{{0, 0, 0}, {1, 1, 1}, Mat3{}};
  const SurfacePoint a = surface_at(box, {-1, 0.2, 0.3});
  const SurfacePoint b = surface_at(box, {-1, 0.3, 0.3});
  EXPECT_NEAR(std::hypot(b.u - a.u, b.v - a.v), 0.1, 1e-12);

  const Shape sphere = Sphere{{0, 0, 0}, 2};
  const SurfacePoint c = surface_at(sphere, {2, 0, 0});
  const SurfacePoint d = surface_at(sphere, {2 * std::cos(0.05), 2 * std::sin(0.05), 0});
  EXPECT_NEAR(std::hypot(d.u - c.u, d.v - c.v), 0.1, 1e-12);
}

TEST(SynthGeometry, OppositeBoxFacesGetDifferentTextureRegions) {
  const Shape box = Box{{0, 0, 0}, {1, 1, 1}, Mat3{}};
  const SurfacePoint left = surface_at(box, {-1, 0.2, 0.3});
  const SurfacePoint right = surface_at(box, {1, 0.2, 0.3});
  EXPECT_GT(std::hypot(right.u - left.u, right.v - left.v), 1);
}

TEST(SynthGeometry, BoundingSphereEnclosesTheBox) {
  const Sphere bound = bounding_sphere(Box{{1, 0, 0}, {1, 2, 2}, rotation_z(0.3)});
  expect_near(bound.center, {1, 0, 0});
  EXPECT_NEAR(bound.radius, 3, 1e-12);
}

}  // namespace
}  // namespace iesrgs::synth
