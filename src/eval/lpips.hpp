#pragma once
// LPIPS v0.1 (Zhang et al. 2018), the learned perceptual distance reported beside PSNR and SSIM:
// an ImageNet AlexNet or VGG16 backbone with the authors' linear heads, both read from the
// official checkpoints by their own parameter names. "vgg-3dgs" is VGG16 scored as 3DGS's and
// Mip-Splatting's metrics scripts score it, which is how the papers built on them report LPIPS:
// with images given in [0, 1] where the official metric expects [-1, 1].
#include <torch/torch.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "priors/state_dict.hpp"

namespace iesrgs::eval {

enum class LpipsNet { Alex, Vgg, Vgg3dgs };

// "alex" and "vgg" (the official names) and "vgg-3dgs"; throws Error for anything else.
LpipsNet parse_lpips_net(const std::string& name);
const char* lpips_net_name(LpipsNet net);

struct LpipsWeights {
  std::filesystem::path backbone;  // torchvision's ImageNet checkpoint (only features.* is used)
  std::filesystem::path heads;     // LPIPS v0.1 linear heads, lin0..lin4
};

// Where the weights are when the user names none. Backbone: $IESRGS_WEIGHTS_DIR/<file> when that
// file exists, else torchvision's download cache $TORCH_HOME/hub/checkpoints/<file> ($TORCH_HOME
// defaults to $XDG_CACHE_HOME/torch, else ~/.cache/torch), with torchvision's file names
// alexnet-owt-7be5be79.pth and vgg16-397923af.pth. Heads: lpips/v0.1/<net>.pth in the weights
// folder the SR checkpoints come from (priors::default_weights_dir).
LpipsWeights default_lpips_weights(LpipsNet net);

// "<path>: no such file (<what it is>)" for the first missing file, nullopt when both exist.
std::optional<std::string> lpips_unavailable_reason(LpipsNet net, const LpipsWeights& weights);

class Lpips {
 public:
  // Reads both checkpoints and builds the metric from them, as below.
  static Lpips load(LpipsNet net, const LpipsWeights& weights);
  // From checkpoints already read, strictly by the official names and shapes; the backbone's
  // entries outside features.* (torchvision's classifier) are ignored. Errors name the file in
  // `weights` that each state dict came from, and the first missing or mis-shaped entry.
  static Lpips from_state_dicts(LpipsNet net, const priors::StateDict& backbone,
                                const priors::StateDict& heads, const LpipsWeights& weights);

  // Smallest width and height the backbone's strides and poolings accept.
  int min_size() const;
  // Moves the networks; distance() then runs there.
  void to(const torch::Device& device);

  // The official lpips(a, b, normalize=True) (normalize=False for vgg-3dgs): RGB images in
  // [0, 1], (3, H, W) or (1, 3, H, W), both the same size. Throws Error for other shapes or
  // images below min_size().
  float distance(const torch::Tensor& a, const torch::Tensor& b) const;

 private:
  struct Networks;
  explicit Lpips(std::shared_ptr<Networks> networks);

  std::shared_ptr<Networks> networks_;
};

// The metric as loaded once for every render it scores, and what a report says of it.
struct LoadedLpips {
  std::optional<Lpips> metric;  // absent for "none" or without its weights
  std::string status;           // the net's name, or why the metric is absent

  const Lpips* get() const { return metric ? &*metric : nullptr; }
};

// The metric from its default weights when a net's name names it and both files exist;
// otherwise no metric, its status saying why ("not computed" for "none", or the missing file).
LoadedLpips load_default_lpips(const std::string& name);

}  // namespace iesrgs::eval
