#pragma once
// Gaussian splat scenes as standard 3DGS .ply files (one "vertex" element, one float property per
// stored parameter), the layout that 3DGS, Mip-Splatting and every splat viewer read and write.
#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "io/non_finite_records.hpp"
#include "io/point_cloud.hpp"

namespace iesrgs {

// The highest SH degree a cloud holds: 3DGS's, and the renderer's.
constexpr int kMaxCloudShDegree = 3;

// Gaussians in 3DGS's raw (pre-activation) storage form, structure of arrays, N Gaussians.
struct SplatCloud {
  int sh_degree = 0;              // 0..3; K = (sh_degree + 1)^2 coefficients per channel
  std::vector<float> positions;   // (N, 3)
  std::vector<float> sh_dc;       // (N, 3)
  std::vector<float> sh_rest;     // (N, K - 1, 3): coefficient-major, like 3DGS's tensor
  std::vector<float> opacity;     // (N), logit
  std::vector<float> log_scales;  // (N, 3)
  std::vector<float> rotations;   // (N, 4), quaternion w x y z, not necessarily normalized
  std::vector<float> filter_3d;   // (N) Mip-Splatting 3D filter std, or empty when absent
  // Trained with Mip-Splatting's 2D mip filter, which renderers must then use; false for 3DGS's
  // dilation. Kept when the 3D filter is baked.
  bool antialiased = true;
  // The background the model was trained over, which renders default to: 3DGS keeps it in the
  // model folder's cfg_args, a .ply in a "comment background r g b" header line that other readers
  // skip. Unset for a file without that line.
  std::optional<std::array<float, 3>> background;

  size_t size() const { return positions.size() / 3; }
  bool has_filter_3d() const { return !filter_3d.empty(); }
};

// binary_little_endian float32 in 3DGS's property order: x y z nx ny nz f_dc_0..2 f_rest_*
// opacity scale_0..2 rot_0..3, then Mip-Splatting's filter_3D when present; the background as a
// comment when set. Normals are written as zeros and f_rest channel-major (all R coefficients,
// then G, then B), as 3DGS flattens its transposed tensor. Written atomically; throws Error naming
// the file when the arrays disagree in size or hold a non-finite value.
void write_ply(const std::filesystem::path& path, const SplatCloud& cloud);

// Throws Error naming `path` when the cloud's arrays disagree with its size and SH degree.
void check_splat_cloud(const SplatCloud& cloud, const std::filesystem::path& path);

// The 3D filter folded into each Gaussian, as Mip-Splatting's "fused" export, so that renderers
// without the filter draw the same: scale sqrt(s^2 + f^2) and opacity
// sigmoid(o) * sqrt(prod(s^2) / prod(s^2 + f^2)), stored as log and logit; no filter_3d left.
// A cloud without the filter comes back unchanged. Expects a checked cloud.
SplatCloud bake_filter_3d(SplatCloud cloud);

// write_ply of the cloud with its 3D filter baked, for viewers that do not know the filter.
void write_ply_filter_baked(const std::filesystem::path& path, const SplatCloud& cloud);

// Reads ascii or binary_little_endian files with the properties in any order and any scalar type;
// unknown properties and elements after the vertex element are skipped. The SH degree follows from
// the number of f_rest properties. A .ply has no flag for the 2D filter: the cloud is antialiased
// when it has Mip-Splatting's filter_3D, which only its trainers write, and otherwise is drawn as
// 3DGS and the viewers draw it (this includes write_ply_filter_baked's own output). A vertex
// holding a value that is not a finite float is left out, with a warning (NonFiniteRecords), or,
// for a file only iesrgs writes (a stage's own model, where one means damage), refused. Throws
// Error naming the file for anything it cannot use.
SplatCloud read_ply(const std::filesystem::path& path, NonFinite non_finite = NonFinite::LeaveOut);

// read_ply on bytes already in memory; `name` is only used in error messages.
SplatCloud parse_ply(std::string_view bytes, const std::filesystem::path& name,
                     NonFinite non_finite = NonFinite::LeaveOut);

// The x y z and red green blue of a point cloud's vertices, as nerfstudio reads a scene's
// ply_file_path: ascii or binary_little_endian, any scalar types, colours as bytes or, stored as
// floats, in [0, 1], and grey where there are none. Other properties are skipped, and a vertex
// whose position is not finite is left out, with a warning. Throws Error naming the file for
// anything it cannot use.
PointCloud read_point_ply(const std::filesystem::path& path);

// read_point_ply on bytes already in memory; `name` is only used in error messages.
PointCloud parse_point_ply(std::string_view bytes, const std::filesystem::path& name);

}  // namespace iesrgs
