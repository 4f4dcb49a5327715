#pragma once
// Niantic's compressed .spz format, version 3 (one gzip stream), which the reference library and
// the viewers that read .spz (SuperSplat, Spark, Babylon.js and others) decode; about a tenth of
// the .ply's size.
#include <filesystem>

#include "io/ply.hpp"

namespace iesrgs {

// A 16-byte header (magic "NGSP", version, count, SH degree, fractional bits, flags) and then, for
// all Gaussians in the cloud's order, one stream per attribute: positions as 24-bit fixed point,
// opacities, colours (0.5 + 0.15 f_dc), log scales, rotations as the smallest three quaternion
// components and higher SH bands quantized to 5 (degree 1) and 4 bits. Coordinates are the
// .ply's, unconverted, as the reference ply_to_spz writes them. The 3D filter is baked in first
// and, when the cloud had one, the "antialiased" flag tells the viewer to use Mip-Splatting's 2D
// filter. Written atomically; throws Error naming the file for a malformed or non-finite cloud.
void write_spz(const std::filesystem::path& path, const SplatCloud& cloud);

}  // namespace iesrgs
