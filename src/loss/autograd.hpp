#pragma once
// SSIM and Pearson correlation as torch autograd functions backed by the CPU kernels, so that they
// compose with tensor losses. CPU tensors, float32 or float64; the second argument is a constant
// target (passing one that requires grad is an error).
#include <ATen/core/Tensor.h>

#include "loss/image_shape.hpp"

namespace iesrgs::loss {

// The shape of a (C, H, W) image tensor; throws Error("<what>: ...") for any other shape.
ImageShape chw_shape(const at::Tensor& image, const char* what);

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

// The fusion stage's texture loss (loss/texture_fusion.hpp) of a render (C, H, W) against the
// internal and external references, `internal_share` (H, W) choosing between them per pixel;
// `internal` may be undefined when the share is zero everywhere. Differentiable in render.
at::Tensor guided_texture_autograd(const at::Tensor& render, const at::Tensor& internal,
                                   const at::Tensor& external, const at::Tensor& internal_share,
                                   double dssim_weight);

// The same loss composed of tensor ops around ssim_autograd, which is what tensors on a GPU take
// (the kernel of loss/texture_fusion.hpp works on host arrays); equal in value and gradient.
at::Tensor guided_texture_from_ops(const at::Tensor& render, const at::Tensor& internal,
                                   const at::Tensor& external, const at::Tensor& internal_share,
                                   double dssim_weight);

}  // namespace iesrgs::loss
