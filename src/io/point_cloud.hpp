#pragma once
// Sparse SfM points: a scene's start for training (COLMAP points3D, nerfstudio's ply_file_path).
#include <array>
#include <cstdint>
#include <vector>

#include "core/math.hpp"

namespace iesrgs {

struct PointCloud {
  std::vector<Vec3> positions;
  std::vector<std::array<uint8_t, 3>> colors;
};

}  // namespace iesrgs
