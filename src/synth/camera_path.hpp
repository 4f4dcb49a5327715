#pragma once
// Where the synthetic scene's cameras stand: on a sphere around the origin, looking at it, with
// NeRF Synthetic's field of view and distance so the scene is framed like its objects.
#include <array>
#include <cstdint>
#include <vector>

#include "core/math.hpp"

namespace iesrgs::synth {

constexpr double kCameraAngleX = 0.6911112070083618;  // radians, as in NeRF Synthetic
constexpr double kOrbitRadius = 4.031128874149275;

// Camera-to-world in the OpenGL / Blender convention: the columns of `axes` are the camera's
// x (right), y (up) and z (backward, the camera looks along -z) in world coordinates.
struct CameraPose {
  Mat3 axes;
  Vec3 position;

  // The 4x4 matrix as transforms.json stores it.
  std::array<std::array<double, 4>, 4> matrix() const;
};

// A camera at `eye` looking at `target`, with the world's +z up in the image.
CameraPose look_at(const Vec3& eye, const Vec3& target);

// Training views spread evenly over the upper hemisphere, 5 to 85 degrees above the horizon
// (a golden-angle spiral; the seed turns it and jitters the heights).
std::vector<CameraPose> train_orbit(int count, uint64_t seed);

// Test views on a two-turn spiral rising from 15 to 45 degrees, so none repeats a training view.
std::vector<CameraPose> test_orbit(int count);

}  // namespace iesrgs::synth
