#pragma once
// The DPT decoder of Depth Anything V2: four transformer feature maps reassembled at 4x, 2x, 1x
// and 1/2x the patch grid, fused coarse to fine, and turned into one non-negative channel at the
// input resolution. Modules are named as in the authors' code ("depth_head.scratch.refinenet1.
// resConfUnit1.conv1.weight", ...) so the official checkpoints load strictly.
#include <torch/torch.h>

#include <array>
#include <vector>

namespace iesrgs::priors::depth {

struct DptConfig {
  int features = 64;
  std::array<int, 4> out_channels{48, 96, 192, 384};
};

// Two ReLU -> 3x3 conv steps around an identity shortcut.
class ResidualConvUnitImpl : public torch::nn::Module {
 public:
  explicit ResidualConvUnitImpl(int features);
  torch::Tensor forward(const torch::Tensor& x);

 private:
  torch::nn::Conv2d conv1_{nullptr}, conv2_{nullptr};
};
TORCH_MODULE(ResidualConvUnit);

class FeatureFusionBlockImpl : public torch::nn::Module {
 public:
  explicit FeatureFusionBlockImpl(int features);
  // Adds the refined `skip` (when defined) to the coarser path `x`, refines the sum, resamples
  // it to `size` (bilinear, corners aligned) and mixes channels with a 1x1 conv.
  torch::Tensor forward(const torch::Tensor& x, const torch::Tensor& skip, torch::IntArrayRef size);

 private:
  torch::nn::Conv2d out_conv_{nullptr};
  ResidualConvUnit skip_unit_{nullptr}, path_unit_{nullptr};
};
TORCH_MODULE(FeatureFusionBlock);

class DptHeadImpl : public torch::nn::Module {
 public:
  // `in_channels`: the encoder's embedding width.
  DptHeadImpl(int in_channels, const DptConfig& config);

  // Patch tokens (B, patch_h * patch_w, C) of four encoder blocks, shallow to deep ->
  // (B, 1, 14 * patch_h, 14 * patch_w).
  torch::Tensor forward(const std::vector<torch::Tensor>& tokens, int64_t patch_h, int64_t patch_w);

 private:
  torch::Tensor reassemble(size_t level, const torch::Tensor& tokens, int64_t patch_h,
                           int64_t patch_w);
  torch::Tensor fuse(const std::array<torch::Tensor, 4>& levels);
  torch::Tensor predict(const torch::Tensor& fused, int64_t height, int64_t width);

  std::vector<torch::nn::Conv2d> projects_;
  std::vector<torch::nn::AnyModule> resize_layers_;
  std::vector<torch::nn::Conv2d> layer_rn_;
  std::vector<FeatureFusionBlock> refinenets_;
  torch::nn::Conv2d output_conv1_{nullptr};
  torch::nn::Sequential output_conv2_{nullptr};
};
TORCH_MODULE(DptHead);

}  // namespace iesrgs::priors::depth
