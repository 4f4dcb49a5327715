#include "priors/sr/safmn.hpp"

#include <vector>

#include "priors/sr/layers.hpp"

namespace iesrgs::priors::sr {

namespace nn = torch::nn;
namespace F = torch::nn::functional;

namespace {

// Spatially-adaptive feature modulation: a quarter of the channels at full resolution and the
// others max-pooled by 4, 8 and 16, each filtered depthwise, brought back by nearest
// upsampling, mixed, and used as a GELU gate on the input.
class SafmImpl : public nn::Module {
 public:
  static constexpr int64_t kLevels = 4;

  explicit SafmImpl(int64_t dim) {
    const int64_t chunk = dim / kLevels;
    mfr_ = register_module("mfr", nn::ModuleList());
    for (int64_t i = 0; i < kLevels; ++i) mfr_->push_back(same_conv(chunk, chunk, 3, false, chunk));
    aggr_ = register_module("aggr", same_conv(dim, dim, 1, false));
  }

  torch::Tensor forward(const torch::Tensor& x) {
    const int64_t h = x.size(2), w = x.size(3);
    const std::vector<torch::Tensor> chunks = x.chunk(kLevels, 1);
    std::vector<torch::Tensor> levels;
    levels.push_back(mfr_[0]->as<nn::Conv2d>()->forward(chunks[0]));
    for (int64_t i = 1; i < kLevels; ++i) {
      const torch::Tensor pooled = F::adaptive_max_pool2d(
          chunks[i], F::AdaptiveMaxPool2dFuncOptions({h >> (i + 1), w >> (i + 1)}));
      const torch::Tensor filtered = mfr_[i]->as<nn::Conv2d>()->forward(pooled);
      levels.push_back(F::interpolate(
          filtered,
          F::InterpolateFuncOptions().size(std::vector<int64_t>{h, w}).mode(torch::kNearest)));
    }
    return torch::gelu(aggr_->forward(torch::cat(levels, 1))) * x;
  }

 private:
  nn::ModuleList mfr_{nullptr};
  nn::Conv2d aggr_{nullptr};
};
TORCH_MODULE(Safm);

// Convolutional channel mixer: 3x3 expansion, GELU, 1x1 projection.
class CcmImpl : public nn::Module {
 public:
  CcmImpl(int64_t dim, double growth) {
    const auto hidden = int64_t(double(dim) * growth);
    ccm_ = register_module("ccm", nn::Sequential(same_conv(dim, hidden, 3, false), nn::GELU(),
                                                 same_conv(hidden, dim, 1, false)));
  }

  torch::Tensor forward(const torch::Tensor& x) { return ccm_->forward(x); }

 private:
  nn::Sequential ccm_{nullptr};
};
TORCH_MODULE(Ccm);

class AttBlockImpl : public nn::Module {
 public:
  AttBlockImpl(int64_t dim, double ffn_scale) {
    safm_ = register_module("safm", Safm(dim));
    ccm_ = register_module("ccm", Ccm(dim, ffn_scale));
  }

  torch::Tensor forward(torch::Tensor x) {
    x = safm_->forward(x) + x;
    return ccm_->forward(x) + x;
  }

 private:
  Safm safm_{nullptr};
  Ccm ccm_{nullptr};
};
TORCH_MODULE(AttBlock);

}  // namespace

// Global response normalization (as in ConvNeXt V2): each channel scaled by its spatial L2 norm
// relative to the mean over channels.
class GrnImpl : public nn::Module {
 public:
  explicit GrnImpl(int64_t dim) {
    gamma_ = register_parameter("gamma", torch::zeros({1, dim, 1, 1}));
    beta_ = register_parameter("beta", torch::zeros({1, dim, 1, 1}));
  }

  torch::Tensor forward(const torch::Tensor& x) {
    const torch::Tensor norms = torch::linalg_vector_norm(x, 2, {2, 3}, true);
    const torch::Tensor relative = norms / (norms.mean(1, true) + 1e-6);
    return gamma_ * (x * relative) + beta_ + x;
  }

 private:
  torch::Tensor gamma_, beta_;
};

SafmnImpl::SafmnImpl(const SafmnOptions& options) : scale_(options.scale) {
  norm_ = register_module("norm", std::make_shared<GrnImpl>(options.dim));
  to_feat_ = register_module("to_feat", same_conv(3, options.dim, 3, true));
  feats_ = register_module("feats", nn::Sequential());
  for (int64_t i = 0; i < options.blocks; ++i)
    feats_->push_back(AttBlock(options.dim, options.ffn_scale));
  to_img_ =
      register_module("to_img", nn::Sequential(same_conv(options.dim, 3 * scale_ * scale_, 3, true),
                                               nn::PixelShuffle(nn::PixelShuffleOptions(scale_))));
}

torch::Tensor SafmnImpl::forward(const torch::Tensor& rgb) {
  const torch::Tensor base = upsample_bilinear(rgb, scale_);
  const torch::Tensor features = feats_->forward(norm_->forward(to_feat_->forward(rgb)));
  return to_img_->forward(features) + base;
}

}  // namespace iesrgs::priors::sr
