#include "eval/lpips.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <system_error>
#include <vector>

#include "core/error.hpp"
#include "core/paths.hpp"
#include "priors/state_dict.hpp"

namespace iesrgs::eval {
namespace {

namespace fs = std::filesystem;
namespace nn = torch::nn;

// Layers are pushed in torchvision's order, so the Sequential numbers its children exactly like
// the checkpoint's "features.<index>.*" entries, ReLUs and poolings included. Both stacks stop at
// LPIPS's last tap: torchvision's final pooling has no weights and nothing reads its output.
nn::Conv2d conv(int64_t in, int64_t out, int64_t kernel, int64_t stride, int64_t padding) {
  return nn::Conv2d(nn::Conv2dOptions(in, out, kernel).stride(stride).padding(padding));
}

nn::Sequential alexnet_features() {
  return nn::Sequential(conv(3, 64, 11, 4, 2), nn::ReLU(),
                        nn::MaxPool2d(nn::MaxPool2dOptions(3).stride(2)), conv(64, 192, 5, 1, 2),
                        nn::ReLU(), nn::MaxPool2d(nn::MaxPool2dOptions(3).stride(2)),
                        conv(192, 384, 3, 1, 1), nn::ReLU(), conv(384, 256, 3, 1, 1), nn::ReLU(),
                        conv(256, 256, 3, 1, 1), nn::ReLU());
}

// VGG16 is configuration "D": 3x3 convolutions with the listed widths, 0 marking a 2x2 pooling.
nn::Sequential vgg16_features() {
  nn::Sequential features;
  int64_t channels = 3;
  for (int64_t width :
       {64, 64, 0, 128, 128, 0, 256, 256, 256, 0, 512, 512, 512, 0, 512, 512, 512}) {
    if (width == 0) {
      features->push_back(nn::MaxPool2d(nn::MaxPool2dOptions(2).stride(2)));
      continue;
    }
    features->push_back(conv(channels, width, 3, 1, 1));
    features->push_back(nn::ReLU());
    channels = width;
  }
  return features;
}

// The ReLUs whose outputs LPIPS compares.
constexpr std::array<size_t, 5> kAlexTaps = {1, 4, 7, 9, 11};   // relu1 .. relu5
constexpr std::array<size_t, 5> kVggTaps = {3, 8, 15, 22, 29};  // relu1_2, 2_2, 3_3, 4_3, 5_3

struct NetSpec {
  const char* name;           // as --lpips takes it
  const char* heads;          // LPIPS's name of the network, which names its heads' file
  const char* backbone;       // for messages
  const char* backbone_file;  // torchvision's
  nn::Sequential (*features)();
  std::array<size_t, 5> taps;
  int min_size;       // smallest side that still leaves every pooling an input
  bool signed_input;  // images mapped from [0, 1] to [-1, 1] first, as the official metric
};

const NetSpec kAlex{"alex",           "alex",    "AlexNet", "alexnet-owt-7be5be79.pth",
                    alexnet_features, kAlexTaps, 31,        true};
const NetSpec kVgg{"vgg", "vgg", "VGG16", "vgg16-397923af.pth", vgg16_features, kVggTaps, 16, true};
const NetSpec kVgg3dgs{"vgg-3dgs",     "vgg",    "VGG16", "vgg16-397923af.pth",
                       vgg16_features, kVggTaps, 16,      false};

constexpr std::array<LpipsNet, 3> kNets = {LpipsNet::Alex, LpipsNet::Vgg, LpipsNet::Vgg3dgs};

const NetSpec& spec(LpipsNet net) {
  switch (net) {
    case LpipsNet::Alex:
      return kAlex;
    case LpipsNet::Vgg:
      return kVgg;
    case LpipsNet::Vgg3dgs:
      return kVgg3dgs;
  }
  fail("unknown LPIPS network");
}

// torch.hub's cache root, where torchvision downloads its checkpoints.
fs::path torch_home() {
  if (auto home = env_path("TORCH_HOME")) return *home;
  return user_cache_dir("torch").value_or(fs::path(".cache") / "torch");
}

bool is_file(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

// A torchvision checkpoint also holds the classifier, which LPIPS does not use.
priors::StateDict features_only(const priors::StateDict& checkpoint) {
  priors::StateDict features;
  for (const auto& [name, tensor] : checkpoint) {
    if (name.rfind("features.", 0) == 0) features.emplace(name, tensor);
  }
  return features;
}

torch::Tensor unit_channels(const torch::Tensor& features) {
  return features / (features.pow(2).sum(1, /*keepdim=*/true).sqrt() + 1e-10);
}

// (1, 3, H, W) float on `device`, mapped from [0, 1] to [-1, 1] when `signed_input`, and then
// through LPIPS's scaling layer, which standardizes by ImageNet's statistics in that range.
torch::Tensor backbone_input(const torch::Tensor& image, const torch::Device& device,
                             bool signed_input) {
  torch::Tensor x = (image.dim() == 3 ? image.unsqueeze(0) : image).to(device, torch::kFloat);
  if (signed_input) x = 2 * x - 1;
  const auto options = torch::TensorOptions().device(device);
  const torch::Tensor shift = torch::tensor({-.030f, -.088f, -.188f}, options).view({1, 3, 1, 1});
  const torch::Tensor scale = torch::tensor({.458f, .448f, .450f}, options).view({1, 3, 1, 1});
  return (x - shift) / scale;
}

void check_image_pair(const torch::Tensor& a, const torch::Tensor& b, int min_size) {
  const bool rgb =
      (a.dim() == 3 && a.size(0) == 3) || (a.dim() == 4 && a.size(0) == 1 && a.size(1) == 3);
  if (!rgb)
    fail("LPIPS: an image must be (3, H, W) or (1, 3, H, W), got {}", fmt::join(a.sizes(), "x"));
  if (a.sizes() != b.sizes()) {
    fail("LPIPS: the images differ in size ({} and {})", fmt::join(a.sizes(), "x"),
         fmt::join(b.sizes(), "x"));
  }
  const int64_t height = a.size(-2), width = a.size(-1);
  if (std::min(height, width) < min_size) {
    fail("LPIPS: images of {}x{} pixels are too small (at least {}x{} needed)", width, height,
         min_size, min_size);
  }
}

}  // namespace

LpipsNet parse_lpips_net(const std::string& name) {
  for (LpipsNet net : kNets) {
    if (name == spec(net).name) return net;
  }
  fail("unknown LPIPS network '{}' (expected alex, vgg or vgg-3dgs)", name);
}

const char* lpips_net_name(LpipsNet net) {
  return spec(net).name;
}

LpipsWeights default_lpips_weights(LpipsNet net) {
  const NetSpec& net_spec = spec(net);
  fs::path backbone = torch_home() / "hub" / "checkpoints" / net_spec.backbone_file;
  if (auto dir = env_path("IESRGS_WEIGHTS_DIR"); dir && is_file(*dir / net_spec.backbone_file))
    backbone = *dir / net_spec.backbone_file;
  return {backbone, priors::default_weights_dir() / "lpips" / "v0.1" /
                        (std::string(net_spec.heads) + ".pth")};
}

std::optional<std::string> lpips_unavailable_reason(LpipsNet net, const LpipsWeights& weights) {
  if (!is_file(weights.backbone)) {
    return fmt::format("{}: no such file (torchvision's ImageNet {} checkpoint)",
                       weights.backbone.string(), spec(net).backbone);
  }
  if (!is_file(weights.heads)) {
    return fmt::format("{}: no such file (LPIPS v0.1 {} linear heads)", weights.heads.string(),
                       spec(net).heads);
  }
  return std::nullopt;
}

// The backbone and the heads are separate modules because each loads strictly from its own file.
struct Lpips::Networks {
  explicit Networks(LpipsNet net)
      : features(backbone->register_module("features", spec(net).features())), net(net) {
    for (size_t k = 0; k < spec(net).taps.size(); ++k) {
      // Official layout lin<k>.model = (dropout, 1x1 convolution without bias); dropout is the
      // identity outside training.
      auto lin = heads->register_module("lin" + std::to_string(k), std::make_shared<nn::Module>());
      lin_models.push_back(lin->register_module(
          "model",
          nn::Sequential(nn::Dropout(),
                         nn::Conv2d(nn::Conv2dOptions(tap_channels(k), 1, 1).bias(false)))));
    }
    backbone->eval();
    heads->eval();
  }

  // Width of the convolution that feeds tap k's ReLU.
  int64_t tap_channels(size_t k) {
    return features[spec(net).taps[k] - 1]->as<nn::Conv2d>()->options.out_channels();
  }

  std::vector<torch::Tensor> tapped_features(const torch::Tensor& input) {
    std::vector<torch::Tensor> tapped;
    torch::Tensor x = input;
    size_t index = 0;
    for (auto& layer : *features) {
      x = layer.forward(x);
      const auto& taps = spec(net).taps;
      if (std::find(taps.begin(), taps.end(), index++) != taps.end()) tapped.push_back(x);
    }
    return tapped;
  }

  std::shared_ptr<nn::Module> backbone = std::make_shared<nn::Module>();
  std::shared_ptr<nn::Module> heads = std::make_shared<nn::Module>();
  nn::Sequential features;
  std::vector<nn::Sequential> lin_models;
  LpipsNet net;  // its spec: taps, smallest size and input range
  torch::Device device = torch::kCPU;
};

Lpips::Lpips(std::shared_ptr<Networks> networks) : networks_(std::move(networks)) {}

Lpips Lpips::load(LpipsNet net, const LpipsWeights& weights) {
  return from_state_dicts(net, priors::read_state_dict(weights.backbone),
                          priors::read_state_dict(weights.heads), weights);
}

Lpips Lpips::from_state_dicts(LpipsNet net, const priors::StateDict& backbone,
                              const priors::StateDict& heads, const LpipsWeights& weights) {
  auto networks = std::make_shared<Networks>(net);
  priors::load_state_dict(*networks->backbone, features_only(backbone), weights.backbone);
  priors::load_state_dict(*networks->heads, heads, weights.heads);
  return Lpips(std::move(networks));
}

int Lpips::min_size() const {
  return spec(networks_->net).min_size;
}

void Lpips::to(const torch::Device& device) {
  networks_->backbone->to(device);
  networks_->heads->to(device);
  networks_->device = device;
}

float Lpips::distance(const torch::Tensor& a, const torch::Tensor& b) const {
  check_image_pair(a, b, spec(networks_->net).min_size);
  torch::NoGradGuard no_grad;
  const auto input = [&](const torch::Tensor& image) {
    return backbone_input(image, networks_->device, spec(networks_->net).signed_input);
  };
  const auto features_a = networks_->tapped_features(input(a));
  const auto features_b = networks_->tapped_features(input(b));
  torch::Tensor total = torch::zeros({}, torch::TensorOptions().device(networks_->device));
  for (size_t k = 0; k < features_a.size(); ++k) {
    const torch::Tensor difference =
        (unit_channels(features_a[k]) - unit_channels(features_b[k])).pow(2);
    total = total + networks_->lin_models[k]->forward(difference).mean();
  }
  return total.item<float>();
}

LoadedLpips load_default_lpips(const std::string& name) {
  if (name == "none") return {std::nullopt, "not computed (--lpips none)"};
  const LpipsNet net = parse_lpips_net(name);
  const LpipsWeights weights = default_lpips_weights(net);
  if (const auto missing = lpips_unavailable_reason(net, weights))
    return {std::nullopt, "unavailable: " + *missing};
  return {Lpips::load(net, weights), name};
}

}  // namespace iesrgs::eval
