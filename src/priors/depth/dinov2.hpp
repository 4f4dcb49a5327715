#pragma once
// The DINOv2 vision transformer that Depth Anything V2 uses as its encoder. Modules are named as
// in the authors' code, so the official checkpoints load by their own parameter names
// ("pretrained.blocks.0.attn.qkv.weight", ...).
#include <torch/torch.h>

#include <vector>

namespace iesrgs::priors::depth {

// DINOv2's patches are 14 pixels wide; the authors' DPT head and input sizes assume it.
constexpr int kDinoPatchSize = 14;

struct VitConfig {
  int embed_dim = 384;
  int depth = 12;
  int num_heads = 6;
  int mlp_ratio = 4;
  int patch_size = kDinoPatchSize;
  // Side of the square patch grid the positional embedding was trained on (518 / 14).
  int pos_grid = 37;
};

class LayerScaleImpl : public torch::nn::Module {
 public:
  explicit LayerScaleImpl(int dim);
  torch::Tensor forward(const torch::Tensor& x) { return x * gamma_; }

 private:
  torch::Tensor gamma_;
};
TORCH_MODULE(LayerScale);

class AttentionImpl : public torch::nn::Module {
 public:
  // `max_scores`: attention scores held at once; the default (128 MiB of float32) computes a
  // 518 x 518 input in one go and bounds memory for very wide or tall ones.
  AttentionImpl(int dim, int num_heads, int64_t max_scores = int64_t(1) << 25);
  torch::Tensor forward(const torch::Tensor& x);

 private:
  int num_heads_;
  int64_t max_scores_;
  torch::nn::Linear qkv_{nullptr}, proj_{nullptr};
};
TORCH_MODULE(Attention);

class MlpImpl : public torch::nn::Module {
 public:
  MlpImpl(int dim, int hidden);
  torch::Tensor forward(const torch::Tensor& x) { return fc2_(torch::gelu(fc1_(x))); }

 private:
  torch::nn::Linear fc1_{nullptr}, fc2_{nullptr};
};
TORCH_MODULE(Mlp);

// Pre-norm transformer block with LayerScale on both residual branches.
class BlockImpl : public torch::nn::Module {
 public:
  explicit BlockImpl(const VitConfig& config);
  torch::Tensor forward(torch::Tensor x);

 private:
  torch::nn::LayerNorm norm1_{nullptr}, norm2_{nullptr};
  Attention attn_{nullptr};
  Mlp mlp_{nullptr};
  LayerScale ls1_{nullptr}, ls2_{nullptr};
};
TORCH_MODULE(Block);

class DinoVisionTransformerImpl : public torch::nn::Module {
 public:
  explicit DinoVisionTransformerImpl(const VitConfig& config);

  // Image (B, 3, H, W), H and W multiples of the patch size -> for each block index in `taken`
  // (ascending), that block's output after the final LayerNorm, patch tokens only: (B, N, C).
  std::vector<torch::Tensor> intermediate_layers(const torch::Tensor& image,
                                                 const std::vector<int>& taken);

  const VitConfig& config() const { return config_; }

 private:
  torch::Tensor tokens(const torch::Tensor& image);
  torch::Tensor positional_embedding(int64_t height, int64_t width);

  VitConfig config_;
  torch::Tensor cls_token_, pos_embed_;
  // Used only for masked pre-training; kept so that checkpoints load strictly.
  torch::Tensor mask_token_;
  torch::nn::Conv2d patch_proj_{nullptr};
  torch::nn::ModuleList blocks_{nullptr};
  torch::nn::LayerNorm norm_{nullptr};
};
TORCH_MODULE(DinoVisionTransformer);

}  // namespace iesrgs::priors::depth
