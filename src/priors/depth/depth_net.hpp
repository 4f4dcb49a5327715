#pragma once
// The common face of every monocular depth backend, so the external depth prior and
// `iesrgs depth` never care which network runs.
#include <torch/torch.h>

#include <filesystem>
#include <memory>
#include <string>

namespace iesrgs::priors::depth {

class DepthNet {
 public:
  virtual ~DepthNet() = default;
  virtual std::string name() const = 0;
  // RGB in [0, 1], shape (1, 3, H, W) -> (H, W) float32 relative inverse depth (larger is
  // nearer, arbitrary scale and shift), computed without autograd; CPU tensors in and out, the
  // network computed on the compute device. Throws iesrgs::Error for any other input shape.
  virtual torch::Tensor predict(const torch::Tensor& rgb) = 0;
};

// Builds the backend `model`: "depth-anything-v2-vits", "-vitb", "-vitl", or "depth-anything-v2"
// to take the encoder from the checkpoint, loading the authors' checkpoint `weights`
// (depth_anything_v2_<encoder>.pth). "none" returns nullptr and logs that the external depth
// loss is off. Throws iesrgs::Error naming the model or file and the problem.
std::unique_ptr<DepthNet> make_depth_net(const std::string& model,
                                         const std::filesystem::path& weights);

}  // namespace iesrgs::priors::depth
