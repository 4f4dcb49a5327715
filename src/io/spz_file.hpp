#pragma once
// Niantic's compressed .spz format, version 3 (one gzip stream), which the reference library and
// the viewers that read .spz (SuperSplat, Spark, Babylon.js and others) decode; about a tenth of
// the .ply's size.
#include <filesystem>
#include <string_view>

#include "io/ply.hpp"

namespace iesrgs {

// A 16-byte header (magic "NGSP", version, count, SH degree, fractional bits, flags) and then, for
// all Gaussians in the cloud's order, one stream per attribute: positions as 24-bit fixed point,
// opacities, colours (0.5 + 0.15 f_dc), log scales, rotations as the smallest three quaternion
// components and higher SH bands quantized to 5 (degree 1) and 4 bits. Coordinates are the
// .ply's, unconverted, as the reference ply_to_spz writes them. The 3D filter is baked in first
// and, for an antialiased cloud, the "antialiased" flag tells the viewer to use Mip-Splatting's
// 2D filter. Written atomically; throws Error naming the file for a malformed or non-finite cloud.
// Returns how many Gaussians it wrote (viewer_cloud leaves out those no viewer can draw).
size_t write_spz(const std::filesystem::path& path, const SplatCloud& cloud);

// Reads versions 2 and 3 (gzip) and 4 (one zstd stream per attribute) into raw 3DGS parameters:
// logit opacities (bytes 0 and 255 half a quantization step inside (0, 1), where they would be
// infinite), colours back to f_dc, unit quaternions. A written 3D filter stays baked in, so the
// cloud has no filter_3d; the "antialiased" flag sets the cloud's. A degree-4 file keeps SH bands
// 0 to 3, with a warning. Throws Error naming the file for anything it cannot decode.
SplatCloud read_spz(const std::filesystem::path& path);

// read_spz on bytes already in memory; `name` is only used in error messages.
SplatCloud parse_spz(std::string_view bytes, const std::filesystem::path& name);

}  // namespace iesrgs
