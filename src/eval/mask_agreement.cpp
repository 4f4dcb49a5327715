#include "eval/mask_agreement.hpp"

#include <torch/torch.h>

#include "loss/fusion.hpp"

namespace iesrgs::eval {

MaskCounts& MaskCounts::operator+=(const MaskCounts& other) {
  pixels += other.pixels;
  mask += other.mask;
  truth_mask += other.truth_mask;
  both += other.both;
  internal_closer += other.internal_closer;
  return *this;
}

MaskCounts mask_counts(const torch::Tensor& internal_image, const torch::Tensor& external_image,
                       const torch::Tensor& truth, double threshold) {
  const torch::Tensor mask = loss::discrepancy(internal_image, external_image) >= threshold;
  const torch::Tensor truth_mask = loss::discrepancy(truth, external_image) >= threshold;
  const torch::Tensor closer =
      (internal_image - truth).abs().mean(0) < (external_image - truth).abs().mean(0);
  const auto count = [](const torch::Tensor& t) { return t.sum().item<int64_t>(); };
  MaskCounts counts;
  counts.pixels = mask.numel();
  counts.mask = count(mask);
  counts.truth_mask = count(truth_mask);
  counts.both = count(mask & truth_mask);
  counts.internal_closer = count(mask & closer);
  return counts;
}

}  // namespace iesrgs::eval
