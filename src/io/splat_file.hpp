#pragma once
// The compact .splat format of the web viewers (antimatter15's splat viewer and the many built on
// it; gsplat and LichtFeld Studio export it too): 32 bytes per Gaussian, no header, colour
// without view dependence.
#include <filesystem>
#include <string_view>

#include "io/ply.hpp"

namespace iesrgs {

constexpr size_t kSplatRecordBytes = 32;

// Per Gaussian, little-endian: position (3 float32), scale (3 float32, activated), colour and
// opacity (4 uint8: 0.5 + C0 * f_dc and sigmoid(opacity), times 255) and the normalized rotation
// quaternion w x y z (4 uint8: q * 128 + 128), the most visible Gaussians first (largest
// prod(scale) * opacity), as the viewers stream them. Mip-Splatting's 3D filter is baked in
// first. Written atomically; throws Error naming the file for a malformed or non-finite cloud.
// Returns how many Gaussians it wrote (viewer_cloud leaves out those no viewer can draw).
size_t write_splat(const std::filesystem::path& path, const SplatCloud& cloud);

// A .splat file as a cloud of SH degree 0, drawn as the viewers draw it (classic 2D dilation, no
// 3D filter). Colour and opacity come back to within their 8-bit steps and rotations to within
// 1/128; a zero scale (a float underflow on export) becomes the smallest normal one and an
// all-zero rotation the identity. A record whose position or scale is not finite is left out,
// with a warning (NonFiniteRecords). Throws Error naming the file when its size is not a whole
// number of records or a record holds a negative scale.
SplatCloud read_splat(const std::filesystem::path& path);

// read_splat on bytes already in memory; `name` is only used in error messages.
SplatCloud parse_splat(std::string_view bytes, const std::filesystem::path& name);

}  // namespace iesrgs
