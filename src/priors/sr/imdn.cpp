#include "priors/sr/imdn.hpp"

#include <fmt/format.h>

#include <string>

#include "core/error.hpp"
#include "priors/sr/layers.hpp"

namespace iesrgs::priors::sr {

namespace nn = torch::nn;

namespace {

constexpr int kBlocks = 6;
constexpr double kImdnSlope = 0.05;  // of every LeakyReLU in IMDN

nn::Conv2d conv(int64_t in, int64_t out, int64_t kernel) {
  return same_conv(in, out, kernel, true);
}

torch::Tensor imdn_leaky(const torch::Tensor& x) {
  return torch::leaky_relu(x, kImdnSlope);
}

// Contrast-aware channel attention: the gate sees each channel's spatial standard deviation
// plus its mean.
class CcaImpl : public nn::Module {
 public:
  explicit CcaImpl(int64_t channels) {
    const int64_t squeezed = channels / 16;
    conv_du_ =
        register_module("conv_du", nn::Sequential(conv(channels, squeezed, 1), nn::ReLU(),
                                                  conv(squeezed, channels, 1), nn::Sigmoid()));
  }

  torch::Tensor forward(const torch::Tensor& x) {
    const torch::Tensor mean = x.mean({2, 3}, true);
    const torch::Tensor deviation = (x - mean).pow(2).mean({2, 3}, true).sqrt();
    return x * conv_du_->forward(deviation + mean);
  }

 private:
  nn::Sequential conv_du_{nullptr};
};
TORCH_MODULE(Cca);

// Information multi-distillation block: three 3x3 stages each keep a quarter of their output
// channels ("distilled") and pass the other three quarters on; a fourth stage maps the last
// remainder to a quarter, and the four quarters are gated by CCA, fused 1x1 and added back.
class ImdModuleImpl : public nn::Module {
 public:
  explicit ImdModuleImpl(int64_t channels)
      : distilled_(channels / 4), remaining_(channels - channels / 4) {
    c1_ = register_module("c1", conv(channels, channels, 3));
    c2_ = register_module("c2", conv(remaining_, channels, 3));
    c3_ = register_module("c3", conv(remaining_, channels, 3));
    c4_ = register_module("c4", conv(remaining_, distilled_, 3));
    c5_ = register_module("c5", conv(channels, channels, 1));
    cca_ = register_module("cca", Cca(distilled_ * 4));
  }

  torch::Tensor forward(const torch::Tensor& input) {
    std::vector<torch::Tensor> distilled;
    torch::Tensor remaining = input;
    for (nn::Conv2d* stage : {&c1_, &c2_, &c3_}) {
      const std::vector<torch::Tensor> parts =
          imdn_leaky((*stage)->forward(remaining)).split_with_sizes({distilled_, remaining_}, 1);
      distilled.push_back(parts[0]);
      remaining = parts[1];
    }
    distilled.push_back(c4_->forward(remaining));
    return c5_->forward(cca_->forward(torch::cat(distilled, 1))) + input;
  }

 private:
  int64_t distilled_, remaining_;
  nn::Conv2d c1_{nullptr}, c2_{nullptr}, c3_{nullptr}, c4_{nullptr}, c5_{nullptr};
  Cca cca_{nullptr};
};
TORCH_MODULE(ImdModule);

}  // namespace

void check_imdn_release(const StateDict& weights, const std::filesystem::path& file) {
  const auto other = [&](const std::string& release) {
    fail_file(file, fmt::format("an {} checkpoint, which this build does not run; the x2, x3 and "
                                "x4 files (IMDN_x<s>.pth) have the layout it runs",
                                release));
  };
  const auto block = weights.lower_bound("block1.");
  if (block != weights.end() && block->first.rfind("block1.", 0) == 0)
    other("IMDN_RTE (the real-time contest network, block*.c* names)");
  // IMDN_AS has the IMDB blocks, but a strided two-layer fea_conv in front of them.
  if (weights.count("fea_conv.0.weight")) other("IMDN_AS (RealSR at the input's own size)");
  if (weights.count("model.0.weight")) other("IMDN_RTC (the real-time x2 network, model.* names)");
}

ImdnImpl::ImdnImpl(const ImdnOptions& options) {
  const int64_t nf = options.channels;
  if (nf < 16) fail("IMDN: {} channels are too few, at least 16 are needed", nf);
  fea_conv_ = register_module("fea_conv", conv(3, nf, 3));
  for (int i = 1; i <= kBlocks; ++i)
    blocks_.emplace_back(register_module("IMDB" + std::to_string(i), ImdModule(nf)));
  c_ = register_module(
      "c", nn::Sequential(conv(nf * kBlocks, nf, 1),
                          nn::LeakyReLU(nn::LeakyReLUOptions().negative_slope(kImdnSlope))));
  lr_conv_ = register_module("LR_conv", conv(nf, nf, 3));
  upsampler_ = register_module(
      "upsampler", nn::Sequential(conv(nf, 3 * options.scale * options.scale, 3),
                                  nn::PixelShuffle(nn::PixelShuffleOptions(options.scale))));
}

torch::Tensor ImdnImpl::forward(const torch::Tensor& rgb) {
  const torch::Tensor features = fea_conv_->forward(rgb);
  std::vector<torch::Tensor> outputs;
  torch::Tensor x = features;
  for (nn::AnyModule& block : blocks_) outputs.push_back(x = block.forward(x));
  return upsampler_->forward(lr_conv_->forward(c_->forward(torch::cat(outputs, 1))) + features);
}

}  // namespace iesrgs::priors::sr
