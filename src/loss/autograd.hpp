#pragma once
// SSIM and Pearson correlation as torch autograd functions backed by the CPU kernels, so that they
// compose with tensor losses. CPU tensors, float32 or float64; the second argument is a constant
// target (passing one that requires grad is an error).
#include <ATen/core/Tensor.h>

namespace iesrgs::loss {

struct SsimTensors {
  at::Tensor mean;  // scalar SSIM
  at::Tensor map;   // (H, W) per-pixel SSIM, channels averaged; its mean is `mean`
};

// SSIM of x against y, both (C, H, W) as the rasterizer renders them; differentiable in x through
// both outputs.
SsimTensors ssim_autograd(const at::Tensor& x, const at::Tensor& y);

// Pearson correlation of a and b (same shape) over the elements where mask is nonzero (all of
// them when mask is undefined); differentiable in a. An undefined correlation is 0.
at::Tensor pearson_autograd(const at::Tensor& a, const at::Tensor& b,
                            const at::Tensor& mask = at::Tensor());

}  // namespace iesrgs::loss
