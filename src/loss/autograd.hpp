#pragma once
// SSIM, Pearson correlation, the covered-depth L1, the photometric loss and the fusion texture
// loss as torch autograd functions backed by the hand-written kernels, so that they compose with
// tensor losses. CPU tensors, float32 or float64, and in a CUDA build float32 tensors on a GPU; the
// second argument is a constant target (passing one that requires grad is an error).
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

// The same composed of tensor ops in float64, which is what tensors on a GPU take (the kernel of
// loss/pearson.hpp works on host arrays); equal in value and gradient, and it reads nothing back to
// the host. `mask` is defined.
at::Tensor pearson_from_ops(const at::Tensor& a, const at::Tensor& b, const at::Tensor& mask);

// The internal depth term (loss/depth_l1.hpp) of a render's depth and alpha (H, W) against the
// reference depth (H, W), differentiable in depth and alpha. On the CPU the hand-written kernel;
// on a GPU covered_depth_l1_from_ops.
at::Tensor covered_depth_l1_autograd(const at::Tensor& depth, const at::Tensor& alpha,
                                     const at::Tensor& reference);

// The same composed of tensor ops, which is what tensors on a GPU take; equal in value and
// gradient, and it reads nothing back to the host.
at::Tensor covered_depth_l1_from_ops(const at::Tensor& depth, const at::Tensor& alpha,
                                     const at::Tensor& reference);

// 3DGS's photometric loss (1 - w) * L1 + w * (1 - SSIM) of a render (C, H, W) against a target,
// differentiable in render. On the CPU one call of the hand-written kernels, which also computes
// the gradient; on a GPU tensor ops around the SSIM kernel.
at::Tensor photometric_autograd(const at::Tensor& render, const at::Tensor& target,
                                double dssim_weight);

// The fusion stage's texture loss (loss/texture_fusion.hpp) of a render (C, H, W) against the
// internal and external references, `internal_share` (H, W) choosing between them per pixel. A
// reference whose share is zero everywhere may be undefined (the internal one for E alone, the
// external one for I alone); on the CPU a share without its reference is an error. Differentiable
// in render.
at::Tensor guided_texture_autograd(const at::Tensor& render, const at::Tensor& internal,
                                   const at::Tensor& external, const at::Tensor& internal_share,
                                   double dssim_weight);

// The same loss composed of tensor ops around ssim_autograd, which is what tensors on a GPU take
// (the kernel of loss/texture_fusion.hpp works on host arrays); equal in value and gradient. It
// evaluates every reference given, and reads nothing back to the host.
at::Tensor guided_texture_from_ops(const at::Tensor& render, const at::Tensor& internal,
                                   const at::Tensor& external, const at::Tensor& internal_share,
                                   double dssim_weight);

}  // namespace iesrgs::loss
