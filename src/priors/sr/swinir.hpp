#pragma once
// SwinIR (Liang et al. 2021, "Image Restoration Using Swin Transformer") for classical and
// lightweight bicubic super-resolution and for real-world super-resolution. Modules and parameters
// carry the names of the authors' models/network_swinir.py, so their checkpoints load as they are.
#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "priors/sr/sr_net.hpp"
#include "priors/state_dict.hpp"

namespace iesrgs::priors::sr {

enum class SwinIRUpsampler {
  PixelShuffle,        // classical SR: conv_before_upsample, upsample (conv + shuffle)^n, conv_last
  PixelShuffleDirect,  // lightweight SR: one conv to 3 * scale^2 channels, one shuffle
  // real-world SR (x2, x4): conv_before_upsample, (nearest x2, conv_up<i>)^n, conv_hr, conv_last
  NearestConv,
};

struct SwinIRConfig {
  int64_t embed_dim = 0;
  std::vector<int64_t> depths;     // Swin blocks per residual group
  std::vector<int64_t> num_heads;  // attention heads per residual group
  int64_t window_size = 8;
  int64_t mlp_hidden_dim = 0;
  int64_t num_feat = 64;  // reconstruction width; not PixelShuffleDirect
  SwinIRUpsampler upsampler = SwinIRUpsampler::PixelShuffle;
  int scale = 0;
  // resi_connection '3conv' (the large real-world model): every residual convolution is a
  // bottleneck at a quarter of the width instead of one 3x3 convolution.
  bool three_conv = false;
};

// The official classical-SR network SwinIR-M (x2, x3, x4, x8).
SwinIRConfig swinir_m_config(int scale);
// The official lightweight network SwinIR-S (x2, x3, x4).
SwinIRConfig swinir_s_config(int scale);
// Reads the configuration off the shapes of an official checkpoint; throws iesrgs::Error naming
// `file` for layouts this implementation does not run (denoising, JPEG artifact removal, ...).
SwinIRConfig infer_swinir_config(const StateDict& weights, const std::filesystem::path& file);

// The convolution that closes each residual group and the body, registered on its owner as
// `name`: one 3x3 convolution ('1conv'), or 3x3 down to a quarter of the width, 1x1 and 3x3 back
// up with LeakyReLU(0.2) between ('3conv').
class ResidualConv {
 public:
  ResidualConv() = default;
  ResidualConv(torch::nn::Module& owner, const std::string& name, int64_t dim, bool three_conv);
  torch::Tensor operator()(const torch::Tensor& x) const;

 private:
  torch::nn::Conv2d single_{nullptr};
  torch::nn::Sequential bottleneck_{nullptr};
};

class SwinIRImpl : public torch::nn::Module {
 public:
  // Throws iesrgs::Error for an inconsistent configuration. Weights start random.
  explicit SwinIRImpl(SwinIRConfig config);

  // RGB in [0, 1], (B, 3, H, W) with H and W multiples of the window -> (B, 3, sH, sW).
  torch::Tensor forward(const torch::Tensor& rgb);

  const SwinIRConfig& config() const { return config_; }

 private:
  torch::Tensor reconstruct(const torch::Tensor& features);

  SwinIRConfig config_;
  torch::nn::Conv2d conv_first_{nullptr};
  torch::nn::LayerNorm patch_norm_{nullptr};
  torch::nn::ModuleList layers_{nullptr};
  torch::nn::LayerNorm norm_{nullptr};
  ResidualConv conv_after_body_;
  torch::nn::Sequential conv_before_upsample_{nullptr};
  torch::nn::Sequential upsample_{nullptr};  // PixelShuffle, PixelShuffleDirect
  std::vector<torch::nn::Conv2d> up_convs_;  // NearestConv: conv_up1, conv_up2
  torch::nn::Conv2d conv_hr_{nullptr};       // NearestConv
  torch::nn::Conv2d conv_last_{nullptr};
};
TORCH_MODULE(SwinIR);

// Runs a SwinIR the way the official test script does: the input is mirrored at the bottom and
// right up to the next whole window past its size, and the output cropped back.
std::unique_ptr<SrNet> swinir_sr(SwinIR net);

// Loads an official SwinIR checkpoint ({"params": ...}), inferring its configuration; `scale`
// must be the checkpoint's. Throws iesrgs::Error naming the file and the problem.
std::unique_ptr<SrNet> make_swinir(const std::filesystem::path& weights, int scale);
// The same with the configuration named explicitly; every checkpoint entry must fit it.
std::unique_ptr<SrNet> make_swinir(const std::filesystem::path& weights,
                                   const SwinIRConfig& config);

}  // namespace iesrgs::priors::sr
