#pragma once
// The common face of every 2D super-resolution backend, so the external stage
// and `iesrgs upscale` never care which network runs.
#include <torch/torch.h>

#include <filesystem>
#include <memory>
#include <string>

namespace iesrgs::priors::sr {

class SrNet {
 public:
  virtual ~SrNet() = default;
  virtual std::string name() const = 0;
  virtual int scale() const = 0;
  // RGB in [0, 1], shape (1, 3, H, W) -> (1, 3, scale * H, scale * W), under
  // torch::NoGradGuard. Any padding the network needs (e.g. to a window
  // multiple) happens inside and is cropped off again.
  virtual torch::Tensor upscale(const torch::Tensor& rgb) = 0;
};

// Builds the backend `model` (bicubic, safmn, imdn, pan, swinir, esrgan-slim,
// esrgan-medium, esrgan-thick) for `scale`, loading `weights` when the model
// has any (an empty path selects the model's default location, if it has one).
// Throws iesrgs::Error naming the model or file and the problem.
std::unique_ptr<SrNet> make_sr_net(const std::string& model, const std::filesystem::path& weights,
                                   int scale);

}  // namespace iesrgs::priors::sr
