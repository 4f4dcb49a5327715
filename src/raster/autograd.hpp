#pragma once
// LibTorch front end of the rasterizer: a differentiable render() for losses written with
// tensors. Float32 tensors, on the CPU or (CUDA builds) a GPU, where the matching kernels run;
// the kernels themselves never see torch.
#include <torch/types.h>

#include <array>

#include "raster/types.hpp"

namespace iesrgs::gs {
struct GaussianModel;
}

namespace iesrgs::raster {

struct GaussianTensors {
  torch::Tensor means;           // (N, 3)
  torch::Tensor log_scales;      // (N, 3)
  torch::Tensor quats;           // (N, 4) w x y z
  torch::Tensor opacity_logits;  // (N)
  torch::Tensor sh_dc;           // (N, 1, 3) SH band 0
  torch::Tensor sh_rest;         // (N, 15, 3) SH bands 1..3
  torch::Tensor filter_std;      // (N) Mip-Splatting 3D filter, no gradient; undefined = none
  int sh_degree = 0;
  bool antialiased = true;  // Mip-Splatting's 2D filter; false: 3DGS's dilation
};

// The tensors of a model: its parameters themselves, so that gradients reach them.
GaussianTensors render_tensors(const gs::GaussianModel& model);

struct RenderOutput {
  torch::Tensor image;  // (3, H, W) over the background
  torch::Tensor alpha;  // (H, W)
  torch::Tensor depth;  // (H, W) alpha-blended camera z; expected depth = depth / alpha
  torch::Tensor radii;  // (N) int32, 0 where not drawn
};

// Densification statistics, in the style of 3DGS: pass (N, 2) zero tensors that require grad;
// after backward, their .grad() holds the screen-space gradient of each mean (NDC units) and
// the sum of its per-pixel absolute values.
struct ViewspaceProbes {
  torch::Tensor grad;
  torch::Tensor abs_grad;
};

// Throws Error on shapes or dtypes the kernels cannot take.
RenderOutput render(const GaussianTensors& gaussians, const RasterCamera<float>& camera,
                    const std::array<float, 3>& background, const ViewspaceProbes& probes = {});

// What the kernels read of `gaussians`, whose tensors must be contiguous float32 and outlive it:
// for calling rasterize_forward and rasterize_backward without autograd (the benchmarks).
GaussianParams<float> kernel_params(const GaussianTensors& gaussians);

}  // namespace iesrgs::raster
