#pragma once
// The common face of every 2D super-resolution backend, so the external stage
// and `iesrgs upscale` never care which network runs.
#include <torch/torch.h>

#include <string>

namespace iesrgs::priors::sr {

class SrNet {
 public:
  virtual ~SrNet() = default;
  virtual std::string name() const = 0;
  virtual int scale() const = 0;
  // RGB in [0, 1], shape (1, 3, H, W) -> (1, 3, scale * H, scale * W), under
  // torch::NoGradGuard; CPU tensors in and out, the networks computed on the compute device. Any
  // padding the network needs (e.g. to a window multiple) happens inside and is cropped off again.
  virtual torch::Tensor upscale(const torch::Tensor& rgb) = 0;
};

}  // namespace iesrgs::priors::sr
