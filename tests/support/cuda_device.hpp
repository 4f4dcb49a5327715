#pragma once
// The GPU training path's tests compare it with the CPU one through LibTorch; they skip where
// LibTorch sees no GPU (CPU-only LibTorch, or no device), as the kernels' own tests do.
#include <gtest/gtest.h>
#include <torch/cuda.h>
#include <torch/types.h>

#define IESRGS_SKIP_WITHOUT_CUDA() \
  if (!torch::cuda::is_available()) GTEST_SKIP() << "LibTorch sees no CUDA device"

namespace iesrgs::testing {

// ||a - b|| / ||b||, both taken to the CPU in double.
inline double relative_difference(const torch::Tensor& a, const torch::Tensor& b) {
  const torch::Tensor x = a.detach().to(torch::kCPU, torch::kDouble);
  const torch::Tensor y = b.detach().to(torch::kCPU, torch::kDouble);
  return (x - y).norm().item<double>() / std::max(y.norm().item<double>(), 1e-30);
}

// A leaf copy of `t` on the GPU that requires grad as `t` does.
inline torch::Tensor on_cuda(const torch::Tensor& t) {
  return t.defined() ? t.detach().to(torch::kCUDA).requires_grad_(t.requires_grad()) : t;
}

}  // namespace iesrgs::testing
