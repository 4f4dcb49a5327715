#include "synth/camera_path.hpp"

#include <cmath>

#include "synth/random.hpp"

namespace iesrgs::synth {

namespace {

constexpr double kDegree = kPi / 180;

Vec3 on_orbit(double elevation, double azimuth) {
  return Vec3{std::cos(azimuth) * std::cos(elevation), std::sin(azimuth) * std::cos(elevation),
              std::sin(elevation)} *
         kOrbitRadius;
}

}  // namespace

std::array<std::array<double, 4>, 4> CameraPose::matrix() const {
  std::array<std::array<double, 4>, 4> m{};
  for (int row = 0; row < 3; ++row) {
    for (int column = 0; column < 3; ++column) m[row][column] = axes(row, column);
    m[row][3] = position[row];
  }
  m[3][3] = 1;
  return m;
}

CameraPose look_at(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = normalized(target - eye);
  const Vec3 right = normalized(forward.cross({0, 0, 1}));
  const Vec3 up = right.cross(forward);
  CameraPose pose;
  pose.axes.m = {right.x, up.x, -forward.x, right.y, up.y, -forward.y, right.z, up.z, -forward.z};
  pose.position = eye;
  return pose;
}

std::vector<CameraPose> train_orbit(int count, uint64_t seed) {
  const double golden_angle = kPi * (3 - std::sqrt(5.0));
  const double lowest = std::sin(5 * kDegree), highest = std::sin(85 * kDegree);
  Rng rng(seed);
  const double turn = rng.uniform(0, 2 * kPi);
  std::vector<CameraPose> poses;
  for (int i = 0; i < count; ++i) {
    // Heights uniform in sin(elevation) cover the band with equal density per area.
    const double height = lowest + (highest - lowest) * (i + rng.uniform(0.1, 0.9)) / count;
    poses.push_back(look_at(on_orbit(std::asin(height), turn + i * golden_angle), {0, 0, 0}));
  }
  return poses;
}

std::vector<CameraPose> test_orbit(int count) {
  std::vector<CameraPose> poses;
  for (int i = 0; i < count; ++i) {
    const double progress = count > 1 ? double(i) / (count - 1) : 0.5;
    const double elevation = (15 + 30 * progress) * kDegree;
    poses.push_back(look_at(on_orbit(elevation, 2 * 2 * kPi * progress), {0, 0, 0}));
  }
  return poses;
}

}  // namespace iesrgs::synth
