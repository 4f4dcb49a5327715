#include "priors/depth/dpt_head.hpp"

#include <fmt/format.h>

#include "priors/depth/dinov2.hpp"
#include "priors/sr/layers.hpp"

namespace iesrgs::priors::depth {

namespace {

using sr::same_conv;
using torch::nn::Conv2d;
using torch::nn::Conv2dOptions;

constexpr int kHiddenChannels = 32;  // fixed in the authors' output convolutions

// Brings the four levels to 4x, 2x, 1x and 1/2x the patch grid.
std::vector<torch::nn::AnyModule> make_resize_layers(const std::array<int, 4>& channels) {
  using torch::nn::ConvTranspose2d;
  using torch::nn::ConvTranspose2dOptions;
  return {
      torch::nn::AnyModule(
          ConvTranspose2d(ConvTranspose2dOptions(channels[0], channels[0], 4).stride(4))),
      torch::nn::AnyModule(
          ConvTranspose2d(ConvTranspose2dOptions(channels[1], channels[1], 2).stride(2))),
      torch::nn::AnyModule(torch::nn::Identity()),
      torch::nn::AnyModule(Conv2d(Conv2dOptions(channels[3], channels[3], 3).stride(2).padding(1))),
  };
}

std::vector<int64_t> spatial_size(const torch::Tensor& x, int64_t factor = 1) {
  return {x.size(2) * factor, x.size(3) * factor};
}

}  // namespace

ResidualConvUnitImpl::ResidualConvUnitImpl(int features)
    : conv1_(register_module("conv1", same_conv(features, features, 3, /*bias=*/true))),
      conv2_(register_module("conv2", same_conv(features, features, 3, /*bias=*/true))) {}

torch::Tensor ResidualConvUnitImpl::forward(const torch::Tensor& x) {
  return conv2_(torch::relu(conv1_(torch::relu(x)))) + x;
}

FeatureFusionBlockImpl::FeatureFusionBlockImpl(int features)
    : out_conv_(register_module("out_conv", Conv2d(Conv2dOptions(features, features, 1)))),
      skip_unit_(register_module("resConfUnit1", ResidualConvUnit(features))),
      path_unit_(register_module("resConfUnit2", ResidualConvUnit(features))) {}

torch::Tensor FeatureFusionBlockImpl::forward(const torch::Tensor& x, const torch::Tensor& skip,
                                              torch::IntArrayRef size) {
  const torch::Tensor sum = skip.defined() ? x + skip_unit_(skip) : x;
  return out_conv_(torch::upsample_bilinear2d(path_unit_(sum), size, /*align_corners=*/true));
}

DptHeadImpl::DptHeadImpl(int in_channels, const DptConfig& config)
    : resize_layers_(make_resize_layers(config.out_channels)) {
  auto projects = register_module("projects", torch::nn::ModuleList());
  auto resize_layers = register_module("resize_layers", torch::nn::ModuleList());
  for (size_t level = 0; level < 4; ++level) {
    projects_.emplace_back(Conv2dOptions(in_channels, config.out_channels[level], 1));
    projects->push_back(projects_.back());
    resize_layers->push_back(resize_layers_[level].ptr());
  }
  // The authors group the fusion part under "scratch", a module with no forward of its own.
  auto scratch = register_module("scratch", std::make_shared<torch::nn::Module>());
  for (size_t level = 0; level < 4; ++level)
    layer_rn_.push_back(scratch->register_module(
        fmt::format("layer{}_rn", level + 1),
        same_conv(config.out_channels[level], config.features, 3, /*bias=*/false)));
  for (size_t level = 0; level < 4; ++level)
    refinenets_.push_back(scratch->register_module(fmt::format("refinenet{}", level + 1),
                                                   FeatureFusionBlock(config.features)));
  const int half = config.features / 2;
  output_conv1_ =
      scratch->register_module("output_conv1", same_conv(config.features, half, 3, /*bias=*/true));
  output_conv2_ = scratch->register_module(
      "output_conv2",
      torch::nn::Sequential(same_conv(half, kHiddenChannels, 3, /*bias=*/true), torch::nn::ReLU(),
                            Conv2d(Conv2dOptions(kHiddenChannels, 1, 1)), torch::nn::ReLU()));
}

torch::Tensor DptHeadImpl::reassemble(size_t level, const torch::Tensor& tokens, int64_t patch_h,
                                      int64_t patch_w) {
  const torch::Tensor grid =
      tokens.permute({0, 2, 1}).reshape({tokens.size(0), tokens.size(2), patch_h, patch_w});
  return resize_layers_[level].forward(projects_[level](grid));
}

// Coarse to fine: each refinenet upsamples the running path to the next finer level's size,
// the finest one to twice its own.
torch::Tensor DptHeadImpl::fuse(const std::array<torch::Tensor, 4>& levels) {
  std::array<torch::Tensor, 4> rn;
  for (size_t level = 0; level < 4; ++level) rn[level] = layer_rn_[level](levels[level]);
  torch::Tensor path = refinenets_[3](rn[3], torch::Tensor(), spatial_size(rn[2]));
  for (size_t level = 3; level-- > 0;) {
    const std::vector<int64_t> size =
        level > 0 ? spatial_size(rn[level - 1]) : spatial_size(rn[0], 2);
    path = refinenets_[level](path, rn[level], size);
  }
  return path;
}

torch::Tensor DptHeadImpl::predict(const torch::Tensor& fused, int64_t height, int64_t width) {
  const torch::Tensor features =
      torch::upsample_bilinear2d(output_conv1_(fused), {height, width}, /*align_corners=*/true);
  return output_conv2_->forward(features);
}

torch::Tensor DptHeadImpl::forward(const std::vector<torch::Tensor>& tokens, int64_t patch_h,
                                   int64_t patch_w) {
  TORCH_CHECK(tokens.size() == 4, "the DPT head takes four feature levels");
  std::array<torch::Tensor, 4> levels;
  for (size_t level = 0; level < 4; ++level)
    levels[level] = reassemble(level, tokens[level], patch_h, patch_w);
  return predict(fuse(levels), kDinoPatchSize * patch_h, kDinoPatchSize * patch_w);
}

}  // namespace iesrgs::priors::depth
