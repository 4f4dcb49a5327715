#pragma once
// SAFMN, the spatially-adaptive feature modulation network (Sun et al., ICCV 2023), in both
// layouts its authors released (sunny2109/SAFMN). Parameter names are the official ones, so
// checkpoints load strictly, and a checkpoint's own names and shapes say which layout and
// configuration it needs (infer_safmn_options).
#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <memory>

#include "priors/state_dict.hpp"

namespace iesrgs::priors::sr {

enum class SafmnRelease {
  // The NTIRE 2023 efficient-SR entry (SAFMN_x4.pth of the development data): a GRN-normalized
  // stem, blocks without LayerNorm and bias-free, and a bilinear image added to the output.
  Ntire2023,
  // The paper's models (basicsr/archs/safmn_arch.py: SAFMN_DF2K_x2/x3/x4, SAFMN_L_*): a
  // LayerNorm before each half of every block, a residual around the blocks, no bilinear image.
  Iccv2023,
};

struct SafmnOptions {
  int64_t dim = 36;
  int64_t blocks = 8;
  double ffn_scale = 2.0;
  int64_t scale = 4;
  SafmnRelease release = SafmnRelease::Ntire2023;
};

// The smallest side the release's deepest SAFM level can max-pool (by 16 in the NTIRE entry, by
// 8 in the paper's models); smaller inputs have to be padded first.
int64_t safmn_min_side(SafmnRelease release);

// The release and configuration of a SAFMN checkpoint, from its parameter names and shapes.
// Throws iesrgs::Error naming `file` when it is not a SAFMN checkpoint.
SafmnOptions infer_safmn_options(const StateDict& weights, const std::filesystem::path& file);

class GrnImpl;

class SafmnImpl : public torch::nn::Module {
 public:
  explicit SafmnImpl(const SafmnOptions& options = {});
  // RGB in [0, 1], (N, 3, H, W) with H, W >= safmn_min_side -> (N, 3, scale * H, scale * W).
  torch::Tensor forward(const torch::Tensor& rgb);

 private:
  SafmnOptions options_;
  std::shared_ptr<GrnImpl> norm_;
  torch::nn::Conv2d to_feat_{nullptr};
  torch::nn::Sequential feats_{nullptr};
  torch::nn::Sequential to_img_{nullptr};
};
TORCH_MODULE(Safmn);

}  // namespace iesrgs::priors::sr
