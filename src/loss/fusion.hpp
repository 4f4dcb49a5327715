#pragma once
// The per-view loss of IE-SRGS's fusion stage: the mask-guided texture loss against the external
// (2D SR) and internal (LR model rendered at HR) images, plus the geometric loss against the
// internal depth (L1) and the external monocular disparity (1 - Pearson correlation). Every term
// can be switched off, so the paper's ablation rows and baselines are settings of this one loss.
#include <torch/types.h>

#include <string>

#include "loss/photometric.hpp"
#include "raster/autograd.hpp"

namespace iesrgs::loss {

// How the texture references are combined per pixel.
enum class TextureGuidance {
  Masked,    // IE-SRGS: the internal image where M(p) = 1, the external one elsewhere
  Average,   // both references, weighted 1/2 each (the ablation before the mask)
  External,  // the external image alone (2D SR -> 3DGS; also bicubic and HR supervision)
  Internal,  // the internal image alone
};

TextureGuidance parse_texture_guidance(
    const std::string& name);  // masked|average|external|internal
const char* texture_guidance_name(TextureGuidance guidance);

struct FusionWeights {
  TextureGuidance texture = TextureGuidance::Masked;
  double dssim_weight = kDssimWeight;  // l of L_tex
  double internal_depth = 1e-3;        // li of L_gem^I; 0 turns the term off
  double external_depth = 1e-4;        // le of L_gem^E; 0 turns the term off
};

// One training view's references at the HR camera's resolution. Undefined tensors are terms the
// run does not have.
struct FusionTargets {
  torch::Tensor external_image;      // (3, H, W) E_image
  torch::Tensor internal_image;      // (3, H, W) I_image
  torch::Tensor internal_share;      // (H, W) float: M for Masked, 0.5 / 0 / 1 for the others
  torch::Tensor internal_depth;      // (H, W) I_depth, expected camera z, 0 where nothing was drawn
  torch::Tensor external_disparity;  // (H, W) E_depth, relative inverse depth

  // The same references on `device`, where the rendered views are.
  FusionTargets to(torch::Device device) const;
};

// D(p) of the paper, (H, W), for diagnostics.
torch::Tensor discrepancy(const torch::Tensor& internal_image, const torch::Tensor& external_image);

// The per-pixel internal share of `guidance`; the mask M(p) = [D(p) >= threshold] for Masked.
torch::Tensor internal_share(TextureGuidance guidance, const torch::Tensor& internal_image,
                             const torch::Tensor& external_image, double threshold);

// Scalar tensors where the render is: nothing here is read back to the host, which would make a
// GPU wait for every step.
struct FusionLossTerms {
  torch::Tensor total;  // differentiable
  // Unweighted and detached, each term's own value (the tests check them one by one); undefined
  // when the term is off.
  torch::Tensor texture, internal_depth, external_depth;
};

FusionLossTerms fusion_loss(const raster::RenderOutput& render, const FusionTargets& targets,
                            const FusionWeights& weights);

}  // namespace iesrgs::loss
