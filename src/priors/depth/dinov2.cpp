#include "priors/depth/dinov2.hpp"

#include <algorithm>
#include <cmath>

namespace iesrgs::priors::depth {

namespace {

constexpr double kLayerNormEps = 1e-6;
// Added to the target grid before deriving the interpolation scale, as the authors do, so that
// floor(grid * scale) cannot fall one short through rounding.
constexpr double kInterpolateOffset = 0.1;

torch::nn::LayerNorm layer_norm(int dim) {
  return torch::nn::LayerNorm(torch::nn::LayerNormOptions({dim}).eps(kLayerNormEps));
}

}  // namespace

LayerScaleImpl::LayerScaleImpl(int dim) : gamma_(register_parameter("gamma", torch::ones(dim))) {}

AttentionImpl::AttentionImpl(int dim, int num_heads, int64_t max_scores)
    : num_heads_(num_heads),
      max_scores_(max_scores),
      qkv_(register_module("qkv", torch::nn::Linear(dim, 3 * dim))),
      proj_(register_module("proj", torch::nn::Linear(dim, dim))) {}

torch::Tensor AttentionImpl::forward(const torch::Tensor& x) {
  const int64_t batch = x.size(0), tokens = x.size(1), dim = x.size(2);
  const int64_t head_dim = dim / num_heads_;
  const torch::Tensor qkv =
      qkv_(x).reshape({batch, tokens, 3, num_heads_, head_dim}).permute({2, 0, 3, 1, 4});
  const torch::Tensor q = qkv[0] * std::pow(double(head_dim), -0.5);
  const torch::Tensor keys_t = qkv[1].transpose(-2, -1);
  // Softmax works row by row, so query rows can go in slices that bound the score matrix.
  const int64_t rows = std::max<int64_t>(1, max_scores_ / (batch * num_heads_ * tokens));
  std::vector<torch::Tensor> slices;
  for (int64_t start = 0; start < tokens; start += rows) {
    const torch::Tensor scores = torch::matmul(q.slice(2, start, start + rows), keys_t);
    slices.push_back(torch::matmul(scores.softmax(-1), qkv[2]));
  }
  return proj_(torch::cat(slices, 2).transpose(1, 2).reshape({batch, tokens, dim}));
}

MlpImpl::MlpImpl(int dim, int hidden)
    : fc1_(register_module("fc1", torch::nn::Linear(dim, hidden))),
      fc2_(register_module("fc2", torch::nn::Linear(hidden, dim))) {}

BlockImpl::BlockImpl(const VitConfig& config)
    : norm1_(register_module("norm1", layer_norm(config.embed_dim))),
      norm2_(register_module("norm2", layer_norm(config.embed_dim))),
      attn_(register_module("attn", Attention(config.embed_dim, config.num_heads))),
      mlp_(register_module("mlp", Mlp(config.embed_dim, config.embed_dim * config.mlp_ratio))),
      ls1_(register_module("ls1", LayerScale(config.embed_dim))),
      ls2_(register_module("ls2", LayerScale(config.embed_dim))) {}

torch::Tensor BlockImpl::forward(torch::Tensor x) {
  x = x + ls1_(attn_(norm1_(x)));
  return x + ls2_(mlp_(norm2_(x)));
}

DinoVisionTransformerImpl::DinoVisionTransformerImpl(const VitConfig& config) : config_(config) {
  const int dim = config.embed_dim;
  const int positions = config.pos_grid * config.pos_grid + 1;  // + class token
  cls_token_ = register_parameter("cls_token", torch::zeros({1, 1, dim}));
  pos_embed_ = register_parameter("pos_embed", torch::zeros({1, positions, dim}));
  mask_token_ = register_parameter("mask_token", torch::zeros({1, dim}));
  auto patch_embed = register_module("patch_embed", std::make_shared<torch::nn::Module>());
  patch_proj_ = patch_embed->register_module(
      "proj", torch::nn::Conv2d(
                  torch::nn::Conv2dOptions(3, dim, config.patch_size).stride(config.patch_size)));
  blocks_ = register_module("blocks", torch::nn::ModuleList());
  for (int i = 0; i < config.depth; ++i) blocks_->push_back(Block(config));
  norm_ = register_module("norm", layer_norm(dim));
}

// The trained square grid resampled bicubically to the image's grid, with the scale factors (not
// the sizes) driving the sampling positions, exactly as the authors' interpolate_pos_encoding.
torch::Tensor DinoVisionTransformerImpl::positional_embedding(int64_t height, int64_t width) {
  const int64_t grid_h = height / config_.patch_size, grid_w = width / config_.patch_size;
  const int64_t trained = config_.pos_grid;
  // The authors return the table untouched only for square images of the trained size.
  if (grid_h * grid_w == trained * trained && height == width) return pos_embed_;
  const int64_t dim = pos_embed_.size(2);
  const torch::Tensor grid =
      pos_embed_.slice(1, 1).reshape({1, trained, trained, dim}).permute({0, 3, 1, 2});
  const torch::Tensor resized =
      torch::upsample_bicubic2d(grid, {grid_h, grid_w}, /*align_corners=*/false,
                                (grid_h + kInterpolateOffset) / double(trained),
                                (grid_w + kInterpolateOffset) / double(trained));
  const torch::Tensor patches = resized.permute({0, 2, 3, 1}).reshape({1, grid_h * grid_w, dim});
  return torch::cat({pos_embed_.slice(1, 0, 1), patches}, 1);
}

torch::Tensor DinoVisionTransformerImpl::tokens(const torch::Tensor& image) {
  const torch::Tensor patches = patch_proj_(image).flatten(2).transpose(1, 2);
  const torch::Tensor cls = cls_token_.expand({image.size(0), -1, -1});
  return torch::cat({cls, patches}, 1) + positional_embedding(image.size(2), image.size(3));
}

std::vector<torch::Tensor> DinoVisionTransformerImpl::intermediate_layers(
    const torch::Tensor& image, const std::vector<int>& taken) {
  TORCH_CHECK(image.size(2) % config_.patch_size == 0 && image.size(3) % config_.patch_size == 0,
              "image sides must be multiples of the patch size");
  std::vector<torch::Tensor> outputs;
  torch::Tensor x = tokens(image);
  for (size_t i = 0; i < blocks_->size() && outputs.size() < taken.size(); ++i) {
    x = blocks_->ptr<BlockImpl>(i)->forward(x);
    if (int(i) == taken[outputs.size()]) outputs.push_back(norm_(x).slice(1, 1));
  }
  TORCH_CHECK(outputs.size() == taken.size(), "taken block indices must ascend within the depth");
  return outputs;
}

}  // namespace iesrgs::priors::depth
