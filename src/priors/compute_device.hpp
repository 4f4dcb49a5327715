#pragma once
// Where the prior networks run: the process's compute device (core/device.hpp), with CPU images
// in and out, since the callers keep their images on the CPU.
#include <torch/torch.h>

#include "core/device.hpp"

namespace iesrgs::priors {

// forward(input) on the compute device, with `module` moved there (a no-op once it is); the
// result comes back to the CPU.
template <class Forward>
torch::Tensor on_compute_device(torch::nn::Module& module, const torch::Tensor& input,
                                Forward&& forward) {
  const torch::Device device = compute_device();
  module.to(device);
  return forward(input.to(device)).to(torch::kCPU);
}

}  // namespace iesrgs::priors
