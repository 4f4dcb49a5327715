#include "priors/sr/pan.hpp"

#include <string>

#include "core/error.hpp"
#include "priors/sr/layers.hpp"

namespace iesrgs::priors::sr {

namespace nn = torch::nn;

namespace {

constexpr double kPanSlope = 0.2;  // of every LeakyReLU in PAN

torch::Tensor pan_leaky(const torch::Tensor& x) {
  return torch::leaky_relu(x, kPanSlope);
}

// Pixel-attention convolution: a 3x3 conv gated per pixel by a 1x1 conv, then another 3x3.
class PaConvImpl : public nn::Module {
 public:
  explicit PaConvImpl(int64_t channels) {
    k2_ = register_module("k2", same_conv(channels, channels, 1, true));
    k3_ = register_module("k3", same_conv(channels, channels, 3, false));
    k4_ = register_module("k4", same_conv(channels, channels, 3, false));
  }

  torch::Tensor forward(const torch::Tensor& x) {
    return k4_->forward(k3_->forward(x) * torch::sigmoid(k2_->forward(x)));
  }

 private:
  nn::Conv2d k2_{nullptr}, k3_{nullptr}, k4_{nullptr};
};
TORCH_MODULE(PaConv);

// Self-calibrated block: half the channels through a plain 3x3 branch, half through PAConv,
// joined by a 1x1 conv and added back.
class ScpaImpl : public nn::Module {
 public:
  explicit ScpaImpl(int64_t channels) {
    const int64_t half = channels / 2;
    conv1_a_ = register_module("conv1_a", same_conv(channels, half, 1, false));
    conv1_b_ = register_module("conv1_b", same_conv(channels, half, 1, false));
    k1_ = register_module("k1", nn::Sequential(same_conv(half, half, 3, false)));
    pa_conv_ = register_module("PAConv", PaConv(half));
    conv3_ = register_module("conv3", same_conv(2 * half, channels, 1, false));
  }

  torch::Tensor forward(const torch::Tensor& x) {
    const torch::Tensor a = pan_leaky(k1_->forward(pan_leaky(conv1_a_->forward(x))));
    const torch::Tensor b = pan_leaky(pa_conv_->forward(pan_leaky(conv1_b_->forward(x))));
    return conv3_->forward(torch::cat({a, b}, 1)) + x;
  }

 private:
  nn::Conv2d conv1_a_{nullptr}, conv1_b_{nullptr}, conv3_{nullptr};
  nn::Sequential k1_{nullptr};
  PaConv pa_conv_{nullptr};
};
TORCH_MODULE(Scpa);

}  // namespace

// Each pixel gated by a 1x1 convolution of its own features.
class PixelAttentionImpl : public nn::Module {
 public:
  explicit PixelAttentionImpl(int64_t channels) {
    conv_ = register_module("conv", same_conv(channels, channels, 1, true));
  }

  torch::Tensor forward(const torch::Tensor& x) { return x * torch::sigmoid(conv_->forward(x)); }

 private:
  nn::Conv2d conv_{nullptr};
};

PanImpl::PanImpl(const PanOptions& options) : scale_(options.scale) {
  if (scale_ < 2 || scale_ > 4) fail("PAN: scale {} is not supported (2, 3 or 4)", scale_);
  const int64_t nf = options.channels, unf = options.upsample_channels;
  conv_first_ = register_module("conv_first", same_conv(3, nf, 3, true));
  trunk_ = register_module("SCPA_trunk", nn::Sequential());
  for (int64_t i = 0; i < options.blocks; ++i) trunk_->push_back(Scpa(nf));
  trunk_conv_ = register_module("trunk_conv", same_conv(nf, nf, 3, true));
  // x4 runs two x2 stages; x2 and x3 a single one.
  const std::vector<int64_t> factors =
      scale_ == 4 ? std::vector<int64_t>{2, 2} : std::vector<int64_t>{scale_};
  for (size_t i = 0; i < factors.size(); ++i) {
    const std::string n = std::to_string(i + 1);
    UpStage stage;
    stage.factor = factors[i];
    stage.upconv = register_module("upconv" + n, same_conv(i == 0 ? nf : unf, unf, 3, true));
    stage.attention = register_module("att" + n, std::make_shared<PixelAttentionImpl>(unf));
    stage.hr_conv = register_module("HRconv" + n, same_conv(unf, unf, 3, true));
    stages_.push_back(stage);
  }
  conv_last_ = register_module("conv_last", same_conv(unf, 3, 3, true));
}

torch::Tensor PanImpl::upsample(UpStage& stage, const torch::Tensor& x) {
  const torch::Tensor up = stage.upconv->forward(upsample_nearest(x, stage.factor));
  return pan_leaky(stage.hr_conv->forward(pan_leaky(stage.attention->forward(up))));
}

torch::Tensor PanImpl::forward(const torch::Tensor& rgb) {
  const torch::Tensor first = conv_first_->forward(rgb);
  torch::Tensor x = first + trunk_conv_->forward(trunk_->forward(first));
  for (UpStage& stage : stages_) x = upsample(stage, x);
  return conv_last_->forward(x) + upsample_bilinear(rgb, scale_);
}

}  // namespace iesrgs::priors::sr
