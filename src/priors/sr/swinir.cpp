#include "priors/sr/swinir.hpp"

#include <cmath>
#include <iterator>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "priors/sr/layers.hpp"
#include "priors/sr/network_sr.hpp"

namespace iesrgs::priors::sr {
namespace {

using torch::indexing::Slice;

// Bounds the (window^2)^2 relative-position index a corrupt checkpoint could ask for.
constexpr int64_t kMaxWindow = 32;
constexpr int kMaxScale = 8;
// The LeakyReLU slope of the real-world models' upsampler and of every '3conv' bottleneck.
constexpr double kRealSrSlope = 0.2;

bool is_power_of_two(int value) {
  return value > 0 && (value & (value - 1)) == 0;
}

// Empty when `config` describes a network this implementation builds.
std::string config_problem(const SwinIRConfig& config) {
  if (config.depths.empty() || config.depths.size() != config.num_heads.size())
    return "needs one depth and one head count per residual group";
  if (config.embed_dim <= 0 || config.mlp_hidden_dim <= 0 || config.num_feat <= 0)
    return "needs positive embedding, MLP and reconstruction widths";
  for (size_t i = 0; i < config.depths.size(); ++i) {
    if (config.depths[i] <= 0) return fmt::format("residual group {} has no blocks", i);
    if (config.num_heads[i] <= 0 || config.embed_dim % config.num_heads[i] != 0)
      return fmt::format("{} heads do not divide the embedding width {}", config.num_heads[i],
                         config.embed_dim);
  }
  if (config.window_size < 2 || config.window_size > kMaxWindow)
    return fmt::format("window size {} is outside 2..{}", config.window_size, kMaxWindow);
  const bool stacked_scale = is_power_of_two(config.scale) || config.scale == 3;
  if (config.scale < 2 || config.scale > kMaxScale ||
      (config.upsampler == SwinIRUpsampler::PixelShuffle && !stacked_scale) ||
      (config.upsampler == SwinIRUpsampler::NearestConv && config.scale != 2 && config.scale != 4))
    return fmt::format("scale x{} is not supported by this upsampler", config.scale);
  if (config.three_conv && config.embed_dim < 4)
    return "a '3conv' bottleneck needs an embedding width of at least 4";
  return {};
}

// (B, L, C) tokens of an H x W image <-> (B, C, H, W) in channels-last memory, both views of
// the same storage, so switching between attention and convolution copies nothing.
torch::Tensor tokens_to_image(const torch::Tensor& tokens, int64_t height, int64_t width) {
  return tokens.transpose(1, 2).view({tokens.size(0), tokens.size(2), height, width});
}

torch::Tensor image_to_tokens(const torch::Tensor& image) {
  return image.flatten(2).transpose(1, 2);
}

// (B, H, W, C) -> (B * windows, window^2, C), windows in row-major order.
torch::Tensor partition_windows(const torch::Tensor& x, int64_t window) {
  return x.view({x.size(0), x.size(1) / window, window, x.size(2) / window, window, x.size(3)})
      .permute({0, 1, 3, 2, 4, 5})
      .reshape({-1, window * window, x.size(3)});
}

torch::Tensor merge_windows(const torch::Tensor& windows, int64_t window, int64_t height,
                            int64_t width) {
  const int64_t channels = windows.size(-1);
  return windows.view({-1, height / window, width / window, window, window, channels})
      .permute({0, 1, 3, 2, 4, 5})
      .reshape({-1, height, width, channels});
}

// Row of the bias table for each (query, key) pair of a window: the pair's offset, both
// components shifted to be non-negative, flattened row-major over (2 * window - 1)^2 offsets.
torch::Tensor relative_position_index(int64_t window) {
  const torch::Tensor cell = torch::arange(window * window, torch::kLong);
  const torch::Tensor row = torch::div(cell, window, "floor");
  const torch::Tensor col = cell.remainder(window);
  const torch::Tensor drow = row.unsqueeze(1) - row.unsqueeze(0) + (window - 1);
  const torch::Tensor dcol = col.unsqueeze(1) - col.unsqueeze(0) + (window - 1);
  return drow * (2 * window - 1) + dcol;
}

// After the cyclic shift the last window row and column hold pixels from opposite image edges;
// labelling the three bands along an axis lets the mask keep them from attending to each other.
torch::Tensor shift_bands(int64_t size, int64_t window) {
  const int64_t shift = window / 2;
  torch::Tensor band = torch::zeros({size});
  band.index_put_({Slice(size - window, size - shift)}, 1);
  band.index_put_({Slice(size - shift, torch::indexing::None)}, 2);
  return band;
}

// (windows, window^2, window^2): 0 within a band, -100 across bands, as the official mask.
torch::Tensor shifted_window_mask(int64_t height, int64_t width, int64_t window) {
  const torch::Tensor labels = shift_bands(height, window).view({1, height, 1, 1}) * 3 +
                               shift_bands(width, window).view({1, 1, width, 1});
  const torch::Tensor windows = partition_windows(labels, window).squeeze(-1);
  return windows.unsqueeze(1).ne(windows.unsqueeze(2)).to(torch::kFloat).mul_(-100.0);
}

// Channels-last weights make oneDNN keep activations channels-last, which is the layout the
// tokens already have; loading copies into them and keeps it.
torch::nn::Conv2d channels_last_conv(int64_t in, int64_t out, int64_t kernel) {
  torch::nn::Conv2d conv = same_conv(in, out, kernel, /*bias=*/true);
  conv->weight.set_data(conv->weight.contiguous(torch::MemoryFormat::ChannelsLast));
  return conv;
}

torch::nn::Conv2d conv3x3(int64_t in, int64_t out) {
  return channels_last_conv(in, out, 3);
}

torch::nn::LeakyReLU leaky_relu(double slope) {
  return torch::nn::LeakyReLU(torch::nn::LeakyReLUOptions().negative_slope(slope));
}

class WindowAttentionImpl : public torch::nn::Module {
 public:
  WindowAttentionImpl(int64_t dim, int64_t heads, int64_t window)
      : heads_(heads), scale_(1.0 / std::sqrt(double(dim / heads))) {
    // Untruncated version of the official std-0.02 initialisation.
    bias_table_ =
        register_parameter("relative_position_bias_table",
                           torch::randn({(2 * window - 1) * (2 * window - 1), heads}) * 0.02);
    bias_index_ = register_buffer("relative_position_index", relative_position_index(window));
    qkv_ = register_module("qkv", torch::nn::Linear(dim, 3 * dim));
    proj_ = register_module("proj", torch::nn::Linear(dim, dim));
  }

  // windows: (B * nW, N, C); mask: (nW, N, N), or undefined for unshifted windows.
  torch::Tensor forward(const torch::Tensor& windows, const torch::Tensor& mask) {
    const int64_t batch = windows.size(0), tokens = windows.size(1), dim = windows.size(2);
    const torch::Tensor qkv =
        qkv_(windows).view({batch, tokens, 3, heads_, dim / heads_}).permute({2, 0, 3, 1, 4});
    torch::Tensor logits = torch::matmul(qkv[0] * scale_, qkv[1].transpose(-2, -1));
    logits.add_(position_bias(tokens));
    if (mask.defined())
      logits.view({-1, mask.size(0), heads_, tokens, tokens}).add_(mask.unsqueeze(1));
    const torch::Tensor mixed = torch::matmul(logits.softmax(-1), qkv[2]);
    return proj_(mixed.transpose(1, 2).reshape({batch, tokens, dim}));
  }

 private:
  torch::Tensor position_bias(int64_t tokens) const {
    return bias_table_.index_select(0, bias_index_.view(-1))
        .view({tokens, tokens, heads_})
        .permute({2, 0, 1});
  }

  int64_t heads_;
  double scale_;
  torch::Tensor bias_table_, bias_index_;
  torch::nn::Linear qkv_{nullptr}, proj_{nullptr};
};
TORCH_MODULE(WindowAttention);

class SwinBlockImpl : public torch::nn::Module {
 public:
  SwinBlockImpl(const SwinIRConfig& config, int64_t heads, bool shifted)
      : window_(config.window_size), shift_(shifted ? config.window_size / 2 : 0) {
    const int64_t dim = config.embed_dim;
    norm1_ = register_module("norm1", torch::nn::LayerNorm(torch::nn::LayerNormOptions({dim})));
    attn_ = register_module("attn", WindowAttention(dim, heads, window_));
    norm2_ = register_module("norm2", torch::nn::LayerNorm(torch::nn::LayerNormOptions({dim})));
    mlp_ = register_module(
        "mlp", torch::nn::Sequential({{"fc1", torch::nn::Linear(dim, config.mlp_hidden_dim)},
                                      {"act", torch::nn::GELU()},
                                      {"fc2", torch::nn::Linear(config.mlp_hidden_dim, dim)}}));
  }

  torch::Tensor forward(const torch::Tensor& tokens, int64_t height, int64_t width,
                        const torch::Tensor& shift_mask) {
    const int64_t batch = tokens.size(0), dim = tokens.size(2);
    torch::Tensor x = norm1_(tokens).view({batch, height, width, dim});
    if (shift_) x = torch::roll(x, {-shift_, -shift_}, {1, 2});
    const torch::Tensor windows = partition_windows(x, window_);
    x = merge_windows(attn_(windows, shift_ ? shift_mask : torch::Tensor()), window_, height,
                      width);
    if (shift_) x = torch::roll(x, {shift_, shift_}, {1, 2});
    torch::Tensor out = tokens + x.view({batch, height * width, dim});
    return out.add_(mlp_->forward(norm2_(out)));
  }

 private:
  int64_t window_, shift_;
  torch::nn::LayerNorm norm1_{nullptr}, norm2_{nullptr};
  WindowAttention attn_{nullptr};
  torch::nn::Sequential mlp_{nullptr};
};
TORCH_MODULE(SwinBlock);

// The official RSTB: Swin blocks, alternately shifted, then a convolution, around a residual.
class ResidualGroupImpl : public torch::nn::Module {
 public:
  ResidualGroupImpl(const SwinIRConfig& config, int64_t depth, int64_t heads) {
    auto group = register_module("residual_group", std::make_shared<torch::nn::Module>());
    blocks_ = group->register_module("blocks", torch::nn::ModuleList());
    for (int64_t i = 0; i < depth; ++i) blocks_->push_back(SwinBlock(config, heads, i % 2 == 1));
    conv_ = ResidualConv(*this, "conv", config.embed_dim, config.three_conv);
  }

  torch::Tensor forward(const torch::Tensor& tokens, int64_t height, int64_t width,
                        const torch::Tensor& shift_mask) {
    torch::Tensor x = tokens;
    for (const auto& block : *blocks_)
      x = block->as<SwinBlockImpl>()->forward(x, height, width, shift_mask);
    return image_to_tokens(conv_(tokens_to_image(x, height, width))).add_(tokens);
  }

 private:
  torch::nn::ModuleList blocks_{nullptr};
  ResidualConv conv_;
};
TORCH_MODULE(ResidualGroup);

// The official Upsample / UpsampleOneStep: convolutions to factor^2 times the channels, each
// followed by a pixel shuffle, so the stages are named upsample.0, upsample.2, ...
torch::nn::Sequential upsample_stages(const SwinIRConfig& config) {
  torch::nn::Sequential stages;
  if (config.upsampler == SwinIRUpsampler::PixelShuffleDirect) {
    stages->push_back(conv3x3(config.embed_dim, 3 * config.scale * config.scale));
    stages->push_back(torch::nn::PixelShuffle(config.scale));
    return stages;
  }
  const int factor = config.scale == 3 ? 3 : 2;
  for (int reached = 1; reached < config.scale; reached *= factor) {
    stages->push_back(conv3x3(config.num_feat, factor * factor * config.num_feat));
    stages->push_back(torch::nn::PixelShuffle(factor));
  }
  return stages;
}

bool has(const StateDict& weights, const std::string& name) {
  return weights.count(name) != 0;
}

std::string block_prefix(size_t layer, int64_t block) {
  return fmt::format("layers.{}.residual_group.blocks.{}.", layer, block);
}

// A (2w - 1)^2-row relative-position table -> w.
int64_t window_from_bias_table(const torch::Tensor& table, const std::filesystem::path& file) {
  const int64_t side = std::lround(std::sqrt(double(table.size(0))));
  if (side * side != table.size(0) || side % 2 == 0)
    fail_file(file, fmt::format("relative_position_bias_table has {} rows, not (2w - 1)^2",
                                table.size(0)));
  return (side + 1) / 2;
}

void infer_residual_groups(const StateDict& weights, const std::filesystem::path& file,
                           SwinIRConfig& config) {
  for (size_t layer = 0; has(weights, block_prefix(layer, 0) + "norm1.weight"); ++layer) {
    int64_t depth = 1;
    while (has(weights, block_prefix(layer, depth) + "norm1.weight")) ++depth;
    const std::string table_name = block_prefix(layer, 0) + "attn.relative_position_bias_table";
    const torch::Tensor* table = find_weight(weights, table_name, 2, file);
    if (!table) fail_file(file, "missing " + table_name);
    config.depths.push_back(depth);
    config.num_heads.push_back(table->size(1));
    // Loading checks that the other groups share the first group's window.
    if (layer == 0) config.window_size = window_from_bias_table(*table, file);
  }
  if (config.depths.empty())
    fail_file(file, "not a SwinIR checkpoint: no layers.0.residual_group.blocks.0 entries");
  const std::string fc1_name = block_prefix(0, 0) + "mlp.fc1.weight";
  const torch::Tensor* fc1 = find_weight(weights, fc1_name, 2, file);
  if (!fc1) fail_file(file, "missing " + fc1_name);
  config.mlp_hidden_dim = fc1->size(0);
}

// Stacked conv + shuffle stages multiply channels by 4 (x2) or 9 (x3) before each shuffle.
int stacked_upsample_scale(const StateDict& weights, const std::filesystem::path& file,
                           int64_t num_feat) {
  int scale = 1;
  for (int stage = 0;; stage += 2) {
    const torch::Tensor* conv =
        find_weight(weights, fmt::format("upsample.{}.weight", stage), 4, file);
    if (!conv) return scale;
    const int64_t out = conv->size(0);
    if (out != 4 * num_feat && out != 9 * num_feat)
      fail_file(file, fmt::format("upsample.{}.weight has {} output channels, not 4 or 9 times {}",
                                  stage, out, num_feat));
    scale *= out == 4 * num_feat ? 2 : 3;
    if (scale > kMaxScale) fail_file(file, "SwinIR upsampler beyond x8");
  }
}

void infer_reconstruction(const StateDict& weights, const std::filesystem::path& file,
                          SwinIRConfig& config) {
  config.three_conv = has(weights, "conv_after_body.0.weight");
  const torch::Tensor* before = find_weight(weights, "conv_before_upsample.0.weight", 4, file);
  if (has(weights, "conv_up1.weight")) {
    if (!before) fail_file(file, "a 'nearest+conv' upsampler without conv_before_upsample.0");
    config.upsampler = SwinIRUpsampler::NearestConv;
    config.num_feat = before->size(0);
    config.scale = has(weights, "conv_up2.weight") ? 4 : 2;
  } else if (before) {
    config.upsampler = SwinIRUpsampler::PixelShuffle;
    config.num_feat = before->size(0);
    config.scale = stacked_upsample_scale(weights, file, config.num_feat);
  } else if (const torch::Tensor* conv = find_weight(weights, "upsample.0.weight", 4, file)) {
    config.upsampler = SwinIRUpsampler::PixelShuffleDirect;
    config.scale = pixel_shuffle_scale(*conv, "upsample.0.weight", file);
  } else {
    fail_file(file,
              "SwinIR checkpoint without an upsampler (denoising or JPEG artifact "
              "removal), not super-resolution");
  }
}

// The official test script always extends by up to a whole window, even a size already a
// multiple of it.
int64_t padded_size(int64_t size, int64_t window) {
  return (size / window + 1) * window;
}

// Source pixel of each padded position: the image mirrored at its far edge with the edge pixel
// repeated (n-2, n-1, n-1, n-2, ...), as the script's flip-and-concatenate. Mirroring again past
// twice the size keeps inputs smaller than the padding well defined.
torch::Tensor mirrored_indices(int64_t size, int64_t padded, const torch::Device& device) {
  const torch::Tensor i =
      torch::arange(padded, torch::dtype(torch::kLong).device(device)).remainder(2 * size);
  return torch::where(i < size, i, (2 * size - 1) - i);
}

torch::Tensor mirror_pad_past_window(const torch::Tensor& rgb, int64_t window) {
  const int64_t height = rgb.size(2), width = rgb.size(3);
  return rgb.index_select(2, mirrored_indices(height, padded_size(height, window), rgb.device()))
      .index_select(3, mirrored_indices(width, padded_size(width, window), rgb.device()));
}

bool is_derived_mask(const std::string& name) {
  static const std::string suffix = ".attn_mask";
  return name.size() >= suffix.size() &&
         name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::unique_ptr<SrNet> load_swinir(StateDict weights, const SwinIRConfig& config,
                                   const std::filesystem::path& file) {
  // Official files store the shifted-window masks for their training patch size; forward
  // computes them for the actual input instead.
  for (auto it = weights.begin(); it != weights.end();)
    it = is_derived_mask(it->first) ? weights.erase(it) : std::next(it);
  SwinIR net(config);
  load_state_dict(*net, weights, file);
  return swinir_sr(std::move(net));
}

// The official classical-SR family: `layers` residual groups of 6 blocks with 6 heads each,
// MLP ratio 2.
SwinIRConfig official_config(int embed_dim, int layers, SwinIRUpsampler upsampler, int scale) {
  SwinIRConfig config;
  config.embed_dim = embed_dim;
  config.depths.assign(size_t(layers), 6);
  config.num_heads.assign(size_t(layers), 6);
  config.mlp_hidden_dim = 2 * embed_dim;
  config.upsampler = upsampler;
  config.scale = scale;
  return config;
}

}  // namespace

ResidualConv::ResidualConv(torch::nn::Module& owner, const std::string& name, int64_t dim,
                           bool three_conv) {
  if (!three_conv) {
    single_ = owner.register_module(name, conv3x3(dim, dim));
    return;
  }
  const int64_t narrow = dim / 4;
  bottleneck_ = owner.register_module(
      name, torch::nn::Sequential(conv3x3(dim, narrow), leaky_relu(kRealSrSlope),
                                  channels_last_conv(narrow, narrow, 1), leaky_relu(kRealSrSlope),
                                  conv3x3(narrow, dim)));
}

torch::Tensor ResidualConv::operator()(const torch::Tensor& x) const {
  return single_ ? single_.ptr()->forward(x) : bottleneck_.ptr()->forward(x);
}

SwinIRConfig swinir_m_config(int scale) {
  return official_config(180, 6, SwinIRUpsampler::PixelShuffle, scale);
}

SwinIRConfig swinir_s_config(int scale) {
  return official_config(60, 4, SwinIRUpsampler::PixelShuffleDirect, scale);
}

SwinIRConfig infer_swinir_config(const StateDict& weights, const std::filesystem::path& file) {
  const torch::Tensor* first = find_weight(weights, "conv_first.weight", 4, file);
  if (!first || first->size(1) != 3)
    fail_file(file, "not an RGB SwinIR checkpoint: no conv_first.weight of shape (C, 3, 3, 3)");
  SwinIRConfig config;
  config.embed_dim = first->size(0);
  infer_residual_groups(weights, file, config);
  infer_reconstruction(weights, file, config);
  if (const std::string problem = config_problem(config); !problem.empty())
    fail_file(file, "unsupported SwinIR configuration: " + problem);
  return config;
}

SwinIRImpl::SwinIRImpl(SwinIRConfig config) : config_(std::move(config)) {
  if (const std::string problem = config_problem(config_); !problem.empty())
    fail("SwinIR configuration: {}", problem);
  const int64_t dim = config_.embed_dim;
  conv_first_ = register_module("conv_first", conv3x3(3, dim));
  auto patch_embed = register_module("patch_embed", std::make_shared<torch::nn::Module>());
  patch_norm_ = patch_embed->register_module(
      "norm", torch::nn::LayerNorm(torch::nn::LayerNormOptions({dim})));
  layers_ = register_module("layers", torch::nn::ModuleList());
  for (size_t i = 0; i < config_.depths.size(); ++i)
    layers_->push_back(ResidualGroup(config_, config_.depths[i], config_.num_heads[i]));
  norm_ = register_module("norm", torch::nn::LayerNorm(torch::nn::LayerNormOptions({dim})));
  conv_after_body_ = ResidualConv(*this, "conv_after_body", dim, config_.three_conv);
  if (config_.upsampler != SwinIRUpsampler::PixelShuffleDirect) {
    conv_before_upsample_ = register_module(
        "conv_before_upsample",
        torch::nn::Sequential(conv3x3(dim, config_.num_feat), torch::nn::LeakyReLU()));
    conv_last_ = register_module("conv_last", conv3x3(config_.num_feat, 3));
  }
  if (config_.upsampler != SwinIRUpsampler::NearestConv) {
    upsample_ = register_module("upsample", upsample_stages(config_));
    return;
  }
  for (int reached = 1, i = 1; reached < config_.scale; reached *= 2, ++i)
    up_convs_.push_back(
        register_module(fmt::format("conv_up{}", i), conv3x3(config_.num_feat, config_.num_feat)));
  conv_hr_ = register_module("conv_hr", conv3x3(config_.num_feat, config_.num_feat));
}

torch::Tensor SwinIRImpl::forward(const torch::Tensor& rgb) {
  const int64_t height = rgb.size(2), width = rgb.size(3), window = config_.window_size;
  if (height % window != 0 || width % window != 0)
    fail("SwinIR: input {}x{} is not a multiple of the window size {}", width, height, window);
  // Every official SR checkpoint uses img_range 1: only the DIV2K mean is taken off.
  const torch::Tensor mean =
      torch::tensor({0.4488f, 0.4371f, 0.4040f}, rgb.options()).view({1, 3, 1, 1});
  const torch::Tensor shallow = conv_first_(rgb - mean);
  torch::Tensor tokens = patch_norm_(image_to_tokens(shallow));
  const torch::Tensor shift_mask = shifted_window_mask(height, width, window).to(rgb.device());
  for (const auto& layer : *layers_)
    tokens = layer->as<ResidualGroupImpl>()->forward(tokens, height, width, shift_mask);
  const torch::Tensor deep =
      conv_after_body_(tokens_to_image(norm_(tokens), height, width)).add_(shallow);
  return reconstruct(deep).add_(mean);
}

torch::Tensor SwinIRImpl::reconstruct(const torch::Tensor& features) {
  if (config_.upsampler == SwinIRUpsampler::PixelShuffleDirect) return upsample_->forward(features);
  torch::Tensor x = conv_before_upsample_->forward(features);
  if (config_.upsampler == SwinIRUpsampler::PixelShuffle) return conv_last_(upsample_->forward(x));
  // Nearest-neighbour steps instead of pixel shuffles, against checkerboard artifacts.
  const auto leaky = torch::nn::functional::LeakyReLUFuncOptions().negative_slope(kRealSrSlope);
  for (torch::nn::Conv2d& conv : up_convs_)
    x = torch::nn::functional::leaky_relu(conv(upsample_nearest(x, 2)), leaky);
  return conv_last_(torch::nn::functional::leaky_relu(conv_hr_(x), leaky));
}

std::unique_ptr<SrNet> swinir_sr(SwinIR net) {
  const SwinIRConfig config = net->config();
  // Not channels-last: the transformer blocks reshape the activations between convolutions.
  return std::make_unique<NetworkSr<SwinIR>>(
      "swinir", std::move(net), config.scale,
      [window = config.window_size](const torch::Tensor& x) {
        return mirror_pad_past_window(x, window);
      },
      /*channels_last=*/false);
}

std::unique_ptr<SrNet> make_swinir(const std::filesystem::path& weights, int scale) {
  if (weights.empty())
    fail(
        "swinir: no checkpoint file given: pass the authors' .pth, e.g. "
        "001_classicalSR_DF2K_s64w8_SwinIR-M_x4.pth, with --weights (upscale) or --sr-weights "
        "(run, external)");
  StateDict state = read_state_dict(weights);
  const SwinIRConfig config = infer_swinir_config(state, weights);
  if (config.scale != scale)
    fail_file(weights,
              fmt::format("a x{} SwinIR checkpoint, but x{} was requested", config.scale, scale));
  return load_swinir(std::move(state), config, weights);
}

std::unique_ptr<SrNet> make_swinir(const std::filesystem::path& weights,
                                   const SwinIRConfig& config) {
  return load_swinir(read_state_dict(weights), config, weights);
}

}  // namespace iesrgs::priors::sr
