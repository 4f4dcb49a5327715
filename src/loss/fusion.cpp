#include "loss/fusion.hpp"

#include <ATen/ATen.h>

#include <vector>

#include "core/error.hpp"
#include "loss/autograd.hpp"
#include "loss/depth_l1.hpp"
#include "loss/texture_fusion.hpp"

namespace iesrgs::loss {

namespace {

constexpr const char* kGuidanceNames[] = {"masked", "average", "external", "internal"};

// A float (H, W) tensor holding its own copy of `values`, whose element type is `source_type`.
template <typename T>
torch::Tensor map_tensor(const std::vector<T>& values, const ImageShape& shape,
                         torch::ScalarType source_type) {
  return torch::from_blob(const_cast<T*>(values.data()), {shape.height, shape.width}, source_type)
      .clone()
      .to(torch::kFloat);
}

// 1 - corr(rendered inverse depth, E_depth) over the covered pixels, as SparseGS relaxes depth.
torch::Tensor external_depth_loss(const raster::RenderOutput& render,
                                  const torch::Tensor& disparity, const torch::Tensor& covered) {
  const torch::Tensor inverse_depth = render.alpha / render.depth.clamp_min(1e-6);
  return 1 - pearson_autograd(inverse_depth, disparity, covered);
}

// The shape of the two images the discrepancy compares, checked as its kernel reads them: float32
// (C, H, W) images in host memory, of one shape.
ImageShape host_image_pair(const torch::Tensor& internal, const torch::Tensor& external) {
  for (const torch::Tensor& image : {internal, external})
    if (!image.defined() || !image.device().is_cpu() || image.scalar_type() != torch::kFloat)
      fail("fusion: the discrepancy takes float32 images in host memory");
  if (internal.sizes() != external.sizes())
    fail("fusion: the internal image's shape {} differs from the external image's {}",
         c10::str(internal.sizes()), c10::str(external.sizes()));
  return chw_shape(internal, "fusion");
}

}  // namespace

FusionTargets FusionTargets::to(torch::Device device) const {
  FusionTargets moved;
  const auto move = [&](const torch::Tensor& t) { return t.defined() ? t.to(device) : t; };
  moved.external_image = move(external_image);
  moved.internal_image = move(internal_image);
  moved.internal_share = move(internal_share);
  moved.internal_depth = move(internal_depth);
  moved.external_disparity = move(external_disparity);
  return moved;
}

TextureGuidance parse_texture_guidance(const std::string& name) {
  for (int i = 0; i < 4; ++i)
    if (name == kGuidanceNames[i]) return TextureGuidance(i);
  fail("unknown texture guidance '{}' (masked, average, external or internal)", name);
}

const char* texture_guidance_name(TextureGuidance guidance) {
  return kGuidanceNames[int(guidance)];
}

torch::Tensor discrepancy(const torch::Tensor& internal_image,
                          const torch::Tensor& external_image) {
  const ImageShape shape = host_image_pair(internal_image, external_image);
  const torch::Tensor internal = internal_image.contiguous(),
                      external = external_image.contiguous();
  return map_tensor(discrepancy_map(internal.data_ptr<float>(), external.data_ptr<float>(), shape),
                    shape, torch::kFloat);
}

torch::Tensor internal_share(TextureGuidance guidance, const torch::Tensor& internal_image,
                             const torch::Tensor& external_image, double threshold) {
  const torch::Tensor& reference = external_image.defined() ? external_image : internal_image;
  const auto options = reference.options();
  const int64_t height = reference.size(1), width = reference.size(2);
  switch (guidance) {
    case TextureGuidance::Masked: {
      const ImageShape shape = host_image_pair(internal_image, external_image);
      const torch::Tensor internal = internal_image.contiguous();
      const torch::Tensor external = external_image.contiguous();
      return map_tensor(discrepancy_mask(internal.data_ptr<float>(), external.data_ptr<float>(),
                                         shape, threshold),
                        shape, torch::kUInt8);
    }
    case TextureGuidance::Average:
      return torch::full({height, width}, 0.5, options);
    case TextureGuidance::External:
      return torch::zeros({height, width}, options);
    case TextureGuidance::Internal:
      return torch::ones({height, width}, options);
  }
  fail("internal_share: invalid guidance");
}

FusionLossTerms fusion_loss(const raster::RenderOutput& render, const FusionTargets& targets,
                            const FusionWeights& weights) {
  const TextureGuidance guidance = weights.texture;
  const bool uses_internal = guidance != TextureGuidance::External;
  const bool uses_external = guidance != TextureGuidance::Internal;
  // Checked from the guidance, not from the share, which on a GPU would mean reading it back.
  const auto reference = [&](bool used, const torch::Tensor& image, const char* what) {
    if (used && !image.defined())
      fail("fusion loss: the {} texture guidance needs the {} image",
           texture_guidance_name(guidance), what);
    return used ? image : torch::Tensor();
  };
  FusionLossTerms terms;
  terms.total = guided_texture_autograd(
      render.image, reference(uses_internal, targets.internal_image, "internal"),
      reference(uses_external, targets.external_image, "external"), targets.internal_share,
      weights.dssim_weight);
  terms.texture = terms.total.detach();
  if (weights.internal_depth > 0 && targets.internal_depth.defined()) {
    const torch::Tensor l =
        covered_depth_l1_autograd(render.depth, render.alpha, targets.internal_depth);
    terms.internal_depth = l.detach();
    terms.total = terms.total + weights.internal_depth * l;
  }
  if (weights.external_depth > 0 && targets.external_disparity.defined()) {
    const torch::Tensor covered = render.alpha.detach() >= kDepthCoverageAlpha;
    const torch::Tensor l = external_depth_loss(render, targets.external_disparity, covered);
    terms.external_depth = l.detach();
    terms.total = terms.total + weights.external_depth * l;
  }
  return terms;
}

}  // namespace iesrgs::loss
