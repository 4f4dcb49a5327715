#pragma once
// Depth Anything V2 (relative depth): a DINOv2 encoder and a DPT head, with the authors'
// infer_image pre- and post-processing around them.
#include <torch/torch.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "priors/depth/depth_net.hpp"
#include "priors/depth/dinov2.hpp"
#include "priors/depth/dpt_head.hpp"
#include "priors/state_dict.hpp"

namespace iesrgs::priors::depth {

struct DepthAnythingConfig {
  VitConfig vit;
  DptConfig head;
  std::vector<int> taken_blocks;  // encoder blocks whose outputs feed the head, ascending
};

// The released configurations "vits", "vitb" and "vitl"; throws Error for any other name.
DepthAnythingConfig depth_anything_config(const std::string& encoder);

// Which released encoder a checkpoint holds, judged by its embedding width; throws Error
// naming `file` when it matches none.
std::string depth_anything_encoder(const StateDict& weights, const std::filesystem::path& file);

class DepthAnythingV2Impl : public torch::nn::Module {
 public:
  explicit DepthAnythingV2Impl(const DepthAnythingConfig& config);
  // Normalized image (B, 3, H, W), sides multiples of the patch size -> relative inverse depth
  // (B, H, W), non-negative.
  torch::Tensor forward(const torch::Tensor& image);

 private:
  std::vector<int> taken_blocks_;
  DinoVisionTransformer pretrained_{nullptr};
  DptHead depth_head_{nullptr};
};
TORCH_MODULE(DepthAnythingV2);

// Builds `config` and loads `weights` into it strictly (errors name `file`), in eval mode.
DepthAnythingV2 load_depth_anything(const DepthAnythingConfig& config, const StateDict& weights,
                                    const std::filesystem::path& file);

// The network input size (height, width) for an image: aspect kept, short side at least
// `short_side`, each side rounded to a multiple of 14 (the authors' "lower_bound" resize).
std::pair<int64_t, int64_t> network_input_size(int64_t height, int64_t width, int short_side);

// RGB (1, 3, H, W) in [0, 1] -> float32 network input: resized to network_input_size by bicubic
// interpolation without antialiasing (cv2's INTER_CUBIC: a = -0.75, pixel centers aligned,
// edges clamped) and normalized with the ImageNet mean and standard deviation.
torch::Tensor network_input(const torch::Tensor& rgb, int short_side);

class DepthAnythingNet : public DepthNet {
 public:
  DepthAnythingNet(DepthAnythingV2 model, std::string name, int short_side = 518);
  std::string name() const override { return name_; }
  // The network output resized back to H x W, bilinearly with corners aligned.
  torch::Tensor predict(const torch::Tensor& rgb) override;

 private:
  DepthAnythingV2 model_;
  std::string name_;
  int short_side_;
};

}  // namespace iesrgs::priors::depth
