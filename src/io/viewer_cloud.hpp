#pragma once
// What the compact viewer formats (.splat, .spz) share: they have no field for Mip-Splatting's 3D
// filter and store activated values, so a cloud is baked and checked before either is written.
#include <cstdint>
#include <filesystem>

#include "io/ply.hpp"

namespace iesrgs {

// The cloud with its 3D filter baked in (bake_filter_3d), less the Gaussians no viewer can draw:
// a non-finite parameter, a scale that overflows once exponentiated, a zero rotation (a warning
// names `path` and says how many). Throws Error naming `path` when the arrays disagree in size or
// no Gaussian is left.
SplatCloud viewer_cloud(const SplatCloud& cloud, const std::filesystem::path& path);

// Length of the quaternion at q[0..3].
double quaternion_norm(const float* q);

// The nearest integer in 0..255.
uint8_t to_byte(double value);

// The opacity logit a byte of sigmoid(opacity) * 255 stands for; bytes 0 and 255, whose logits
// would be -inf and +inf, are taken half a step inside.
float opacity_logit_of_byte(uint8_t byte);

}  // namespace iesrgs
