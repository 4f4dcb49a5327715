#pragma once
// IMDN, the information multi-distillation network (Hui et al., ACM MM 2019), as released with
// IMDN_x4.pth: six distillation blocks with contrast-aware channel attention, a 1x1 fusion of
// all block outputs and a pixel-shuffle upsampler. Parameter names are the official ones
// (IMDB1..IMDB6, c.0, upsampler.0, ...), so checkpoints load strictly.
#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <vector>

#include "priors/state_dict.hpp"

namespace iesrgs::priors::sr {

struct ImdnOptions {
  int64_t channels = 64;  // at least 16: the attention squeezes a quarter of them 16-fold
  int64_t scale = 4;
};

// Refuses, by name, the authors' other IMDN releases, whose layouts differ from the x2/x3/x4 one:
// IMDN_AS (RealSR at the input's size) and the real-time IMDN_RTC and IMDN_RTE. Throws
// iesrgs::Error naming `file`; a checkpoint of the released layout passes, and the strict load
// names what any other layout lacks.
void check_imdn_release(const StateDict& weights, const std::filesystem::path& file);

class ImdnImpl : public torch::nn::Module {
 public:
  explicit ImdnImpl(const ImdnOptions& options = {});
  // RGB in [0, 1], (N, 3, H, W) -> (N, 3, scale * H, scale * W).
  torch::Tensor forward(const torch::Tensor& rgb);

 private:
  torch::nn::Conv2d fea_conv_{nullptr};
  std::vector<torch::nn::AnyModule> blocks_;
  torch::nn::Sequential c_{nullptr};
  torch::nn::Conv2d lr_conv_{nullptr};
  torch::nn::Sequential upsampler_{nullptr};
};
TORCH_MODULE(Imdn);

}  // namespace iesrgs::priors::sr
