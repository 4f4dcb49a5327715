#pragma once
// SAFMN, the spatially-adaptive feature modulation network (Sun et al., ICCV 2023), in the
// variant of its authors' NTIRE 2023 efficient-SR release, whose x4 checkpoint SAFMN_x4.pth is:
// a GRN-normalized stem, blocks without LayerNorm, and a bilinear image added to the output.
// Parameter names are the official ones, so checkpoints load strictly.
#include <torch/torch.h>

#include <cstdint>
#include <memory>

namespace iesrgs::priors::sr {

struct SafmnOptions {
  int64_t dim = 36;
  int64_t blocks = 8;
  double ffn_scale = 2.0;
  int64_t scale = 4;
};

// The deepest of SAFM's four levels max-pools each side down by 16, so smaller inputs have to be
// padded first.
constexpr int64_t kSafmnMinSide = 16;

class GrnImpl;

class SafmnImpl : public torch::nn::Module {
 public:
  explicit SafmnImpl(const SafmnOptions& options = {});
  // RGB in [0, 1], (N, 3, H, W) with H, W >= kSafmnMinSide -> (N, 3, scale * H, scale * W).
  torch::Tensor forward(const torch::Tensor& rgb);

 private:
  int64_t scale_;
  std::shared_ptr<GrnImpl> norm_;
  torch::nn::Conv2d to_feat_{nullptr};
  torch::nn::Sequential feats_{nullptr};
  torch::nn::Sequential to_img_{nullptr};
};
TORCH_MODULE(Safmn);

}  // namespace iesrgs::priors::sr
