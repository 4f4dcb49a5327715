#pragma once
// The trainable Gaussian scene: 3DGS's parameters as LibTorch leaf tensors (float32, on the CPU
// or the GPU that trains them), in the raw pre-activation form that the rasterizer, the optimizer
// and the PLY files share.
#include <torch/types.h>

#include <array>
#include <cstdint>
#include <vector>

#include "io/camera.hpp"
#include "io/ply.hpp"
#include "io/scene.hpp"

namespace iesrgs::gs {

// The optimized tensors, in the order the optimizer keeps its groups.
enum class Param { Means, ShDc, ShRest, OpacityLogits, LogScales, Quats };
constexpr int kParamCount = 6;

// The parameter's name as GaussianModel's member, which checkpoints and messages use.
const char* param_name(Param p);

struct GaussianModel {
  torch::Tensor means;           // (N, 3)
  torch::Tensor sh_dc;           // (N, 1, 3)
  torch::Tensor sh_rest;         // (N, 15, 3)
  torch::Tensor opacity_logits;  // (N)
  torch::Tensor log_scales;      // (N, 3)
  torch::Tensor quats;           // (N, 4) w x y z
  torch::Tensor filter_3d;       // (N) Mip-Splatting 3D filter std, not optimized; undefined = none
  int active_sh_degree = 0;
  bool antialiased = true;  // drawn with Mip-Splatting's 2D filter (what training uses)

  int64_t size() const { return means.size(0); }
  torch::Tensor& param(Param p);
  const torch::Tensor& param(Param p) const;

  // A copy that shares no storage with this model. Copying the struct shares the tensors, and
  // the optimizer updates them in place, so training such a copy would change this model too.
  GaussianModel clone() const;
  // clone() on `device` (the CPU, or a GPU to train there).
  GaussianModel to(torch::Device device) const;

  // The optimized tensor becomes a contiguous copy of `value`, a fresh leaf that requires grad.
  void set_param(Param p, const torch::Tensor& value);
  void set_params(const std::array<torch::Tensor, kParamCount>& values);
};

// 3DGS's initialization from points with colors in [0, 1] ((N, 3) each): SH DC from the color,
// isotropic scale sqrt of the mean squared distance to the 3 nearest neighbours (at least
// 1e-7 before the root), identity rotation, opacity 0.1, SH degree 0 active. No 3D filter.
GaussianModel model_from_points(const std::vector<float>& positions,
                                const std::vector<float>& colors);

// From SfM points (colors 0..255).
GaussianModel model_from_point_cloud(const PointCloud& cloud);

// 3DGS's NeRF-Synthetic start: `count` points uniform in the cube of half-size `half_extent`
// around `center` (3DGS: 1.3 around the origin) whose SH DC is uniform in [0, 1/255), i.e.
// near-gray colors, exactly as its random init produces.
GaussianModel model_from_random_box(int count, float half_extent, uint64_t seed,
                                    const Vec3& center = {});

// Recomputes the Mip-Splatting 3D filter from the training cameras.
void update_filter_3d(GaussianModel& model, const std::vector<Camera>& cameras);

// SplatCloud at SH degree 3 (all 15 rest coefficients, as 3DGS saves), with filter_3d when
// the model has one.
SplatCloud to_splat_cloud(const GaussianModel& model);

// Clouds of lower SH degree get zero higher bands; the active degree is the cloud's. Throws
// Error when the cloud's arrays disagree in size.
GaussianModel model_from_splat_cloud(const SplatCloud& cloud);

}  // namespace iesrgs::gs
