#pragma once
// PAN, the pixel attention network (Zhao et al., ECCV 2020 workshops), as released with
// PAN_x4.pth: self-calibrated pixel-attention (SCPA) blocks, nearest-neighbour upsampling
// stages with pixel attention, and a bilinear image added to the output. Parameter names are
// the official ones (SCPA_trunk.*, upconv1, att1.conv, HRconv1, ...), so checkpoints load strictly.
#include <torch/torch.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace iesrgs::priors::sr {

struct PanOptions {
  int64_t channels = 40;           // nf
  int64_t upsample_channels = 24;  // unf
  int64_t blocks = 16;             // nb
  int64_t scale = 4;               // 2, 3 or 4
};

class PixelAttentionImpl;

class PanImpl : public torch::nn::Module {
 public:
  explicit PanImpl(const PanOptions& options = {});
  // RGB in [0, 1], (N, 3, H, W) -> (N, 3, scale * H, scale * W).
  torch::Tensor forward(const torch::Tensor& rgb);

 private:
  // One nearest-neighbour upsampling by `factor`, then conv, pixel attention and conv.
  struct UpStage {
    int64_t factor = 1;
    torch::nn::Conv2d upconv{nullptr};
    std::shared_ptr<PixelAttentionImpl> attention;
    torch::nn::Conv2d hr_conv{nullptr};
  };

  torch::Tensor upsample(UpStage& stage, const torch::Tensor& x);

  int64_t scale_;
  torch::nn::Conv2d conv_first_{nullptr};
  torch::nn::Sequential trunk_{nullptr};
  torch::nn::Conv2d trunk_conv_{nullptr};
  std::vector<UpStage> stages_;
  torch::nn::Conv2d conv_last_{nullptr};
};
TORCH_MODULE(Pan);

}  // namespace iesrgs::priors::sr
