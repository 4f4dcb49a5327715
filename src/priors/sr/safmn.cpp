#include "priors/sr/safmn.hpp"

#include <fmt/format.h>

#include <cmath>
#include <vector>

#include "core/error.hpp"
#include "priors/sr/layers.hpp"

namespace iesrgs::priors::sr {

namespace nn = torch::nn;
namespace F = torch::nn::functional;

namespace {

bool is_paper_release(SafmnRelease release) {
  return release == SafmnRelease::Iccv2023;
}

// Spatially-adaptive feature modulation: a quarter of the channels at full resolution and the
// others max-pooled (by 2, 4 and 8 in the paper's models, by 4, 8 and 16 in the NTIRE entry),
// each filtered depthwise, brought back by nearest upsampling, mixed, and used as a GELU gate on
// the input.
class SafmImpl : public nn::Module {
 public:
  static constexpr int64_t kLevels = 4;

  SafmImpl(int64_t dim, SafmnRelease release)
      : first_pool_shift_(is_paper_release(release) ? 1 : 2) {
    const int64_t chunk = dim / kLevels;
    const bool bias = is_paper_release(release);
    mfr_ = register_module("mfr", nn::ModuleList());
    for (int64_t i = 0; i < kLevels; ++i) mfr_->push_back(same_conv(chunk, chunk, 3, bias, chunk));
    aggr_ = register_module("aggr", same_conv(dim, dim, 1, bias));
  }

  torch::Tensor forward(const torch::Tensor& x) {
    const int64_t h = x.size(2), w = x.size(3);
    const std::vector<torch::Tensor> chunks = x.chunk(kLevels, 1);
    std::vector<torch::Tensor> levels;
    levels.push_back(mfr_[0]->as<nn::Conv2d>()->forward(chunks[0]));
    for (int64_t i = 1; i < kLevels; ++i) {
      const int64_t shift = first_pool_shift_ + i - 1;
      const torch::Tensor pooled = F::adaptive_max_pool2d(
          chunks[i], F::AdaptiveMaxPool2dFuncOptions({h >> shift, w >> shift}));
      const torch::Tensor filtered = mfr_[i]->as<nn::Conv2d>()->forward(pooled);
      levels.push_back(F::interpolate(
          filtered,
          F::InterpolateFuncOptions().size(std::vector<int64_t>{h, w}).mode(torch::kNearest)));
    }
    return torch::gelu(aggr_->forward(torch::cat(levels, 1))) * x;
  }

 private:
  int64_t first_pool_shift_;
  nn::ModuleList mfr_{nullptr};
  nn::Conv2d aggr_{nullptr};
};
TORCH_MODULE(Safm);

// Convolutional channel mixer: 3x3 expansion, GELU, 1x1 projection.
class CcmImpl : public nn::Module {
 public:
  CcmImpl(int64_t dim, double growth, bool bias) {
    const auto hidden = int64_t(double(dim) * growth);
    ccm_ = register_module("ccm", nn::Sequential(same_conv(dim, hidden, 3, bias), nn::GELU(),
                                                 same_conv(hidden, dim, 1, bias)));
  }

  torch::Tensor forward(const torch::Tensor& x) { return ccm_->forward(x); }

 private:
  nn::Sequential ccm_{nullptr};
};
TORCH_MODULE(Ccm);

// LayerNorm over the channels of an NCHW tensor, computed as the official module does (its own
// mean and variance, not F.layer_norm over a permuted tensor).
class ChannelLayerNormImpl : public nn::Module {
 public:
  explicit ChannelLayerNormImpl(int64_t dim) {
    weight_ = register_parameter("weight", torch::ones({dim}));
    bias_ = register_parameter("bias", torch::zeros({dim}));
  }

  torch::Tensor forward(const torch::Tensor& x) {
    const torch::Tensor centred = x - x.mean(1, true);
    const torch::Tensor normalized = centred / torch::sqrt(centred.pow(2).mean(1, true) + 1e-6);
    return weight_.view({1, -1, 1, 1}) * normalized + bias_.view({1, -1, 1, 1});
  }

 private:
  torch::Tensor weight_, bias_;
};
TORCH_MODULE(ChannelLayerNorm);

class AttBlockImpl : public nn::Module {
 public:
  AttBlockImpl(int64_t dim, double ffn_scale, SafmnRelease release) {
    if (is_paper_release(release)) {
      norm1_ = register_module("norm1", ChannelLayerNorm(dim));
      norm2_ = register_module("norm2", ChannelLayerNorm(dim));
    }
    safm_ = register_module("safm", Safm(dim, release));
    ccm_ = register_module("ccm", Ccm(dim, ffn_scale, is_paper_release(release)));
  }

  torch::Tensor forward(torch::Tensor x) {
    x = safm_->forward(norm1_ ? norm1_->forward(x) : x) + x;
    return ccm_->forward(norm2_ ? norm2_->forward(x) : x) + x;
  }

 private:
  ChannelLayerNorm norm1_{nullptr}, norm2_{nullptr};
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

int64_t safmn_min_side(SafmnRelease release) {
  return is_paper_release(release) ? 8 : 16;
}

SafmnOptions infer_safmn_options(const StateDict& weights, const std::filesystem::path& file) {
  const torch::Tensor* stem = find_weight(weights, "to_feat.weight", 4, file);
  const torch::Tensor* head = find_weight(weights, "to_img.0.weight", 4, file);
  const torch::Tensor* expansion = find_weight(weights, "feats.0.ccm.ccm.0.weight", 4, file);
  if (!stem || !head || !expansion || stem->size(1) != 3)
    fail_file(file,
              "not an RGB SAFMN checkpoint: needs to_feat.weight of shape (C, 3, 3, 3), "
              "feats.0.ccm.ccm.0.weight and to_img.0.weight");
  SafmnOptions options;
  options.dim = stem->size(0);
  if (options.dim % SafmImpl::kLevels != 0)
    fail_file(file, fmt::format("{} feature channels, not a multiple of SAFM's {} levels",
                                options.dim, SafmImpl::kLevels));
  if (weights.count("norm.gamma")) {
    options.release = SafmnRelease::Ntire2023;
  } else if (weights.count("feats.0.norm1.weight")) {
    options.release = SafmnRelease::Iccv2023;
  } else {
    fail_file(file,
              "a SAFMN checkpoint of neither released layout: no norm.gamma (NTIRE 2023 entry) "
              "and no feats.0.norm1.weight (the paper's models)");
  }
  options.blocks = 0;
  while (weights.count(fmt::format("feats.{}.ccm.ccm.0.weight", options.blocks))) ++options.blocks;
  // The official width is int(dim * ffn_scale); the middle of the scales that truncate to the
  // file's width gives it back whatever the rounding.
  options.ffn_scale = (double(expansion->size(0)) + 0.5) / double(options.dim);
  options.scale = pixel_shuffle_scale(*head, "to_img.0.weight", file);
  return options;
}

SafmnImpl::SafmnImpl(const SafmnOptions& options) : options_(options) {
  if (!is_paper_release(options_.release))
    norm_ = register_module("norm", std::make_shared<GrnImpl>(options_.dim));
  to_feat_ = register_module("to_feat", same_conv(3, options_.dim, 3, true));
  feats_ = register_module("feats", nn::Sequential());
  for (int64_t i = 0; i < options_.blocks; ++i)
    feats_->push_back(AttBlock(options_.dim, options_.ffn_scale, options_.release));
  const int64_t scale = options_.scale;
  to_img_ =
      register_module("to_img", nn::Sequential(same_conv(options_.dim, 3 * scale * scale, 3, true),
                                               nn::PixelShuffle(nn::PixelShuffleOptions(scale))));
}

torch::Tensor SafmnImpl::forward(const torch::Tensor& rgb) {
  const torch::Tensor features = to_feat_->forward(rgb);
  if (is_paper_release(options_.release))
    return to_img_->forward(feats_->forward(features) + features);
  const torch::Tensor base = upsample_bilinear(rgb, options_.scale);
  return to_img_->forward(feats_->forward(norm_->forward(features))) + base;
}

}  // namespace iesrgs::priors::sr
