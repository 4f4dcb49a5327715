#include "eval/mask_agreement.hpp"

#include <torch/torch.h>

#include "eval/metrics.hpp"
#include "loss/fusion.hpp"

namespace iesrgs::eval {

MaskCounts& MaskCounts::operator+=(const MaskCounts& other) {
  pixels += other.pixels;
  values += other.values;
  mask += other.mask;
  truth_mask += other.truth_mask;
  both += other.both;
  closer += other.closer;
  internal_closer += other.internal_closer;
  external_error += other.external_error;
  internal_error += other.internal_error;
  fused_error += other.fused_error;
  oracle_error += other.oracle_error;
  return *this;
}

double MaskCounts::psnr(double squared_error) const {
  return psnr_from_mse(squared_error / double(values));
}

torch::Tensor oracle_mask(const torch::Tensor& internal_image, const torch::Tensor& external_image,
                          const torch::Tensor& truth) {
  return (internal_image - truth).abs().mean(0) < (external_image - truth).abs().mean(0);
}

MaskCounts mask_counts(const torch::Tensor& internal_image, const torch::Tensor& external_image,
                       const torch::Tensor& truth, double threshold) {
  const torch::Tensor mask = loss::discrepancy(internal_image, external_image) >= threshold;
  const torch::Tensor truth_mask = loss::discrepancy(truth, external_image) >= threshold;
  const torch::Tensor closer = oracle_mask(internal_image, external_image, truth);
  const torch::Tensor fused = torch::where(mask, internal_image, external_image);
  const torch::Tensor oracle = torch::where(closer, internal_image, external_image);
  const auto count = [](const torch::Tensor& t) { return t.sum().item<int64_t>(); };
  const auto squared_error = [&](const torch::Tensor& t) {
    return (t - truth).square().sum().item<double>();
  };
  MaskCounts counts;
  counts.pixels = mask.numel();
  counts.values = truth.numel();
  counts.mask = count(mask);
  counts.truth_mask = count(truth_mask);
  counts.both = count(mask & truth_mask);
  counts.closer = count(closer);
  counts.internal_closer = count(mask & closer);
  counts.external_error = squared_error(external_image);
  counts.internal_error = squared_error(internal_image);
  counts.fused_error = squared_error(fused);
  counts.oracle_error = squared_error(oracle);
  return counts;
}

}  // namespace iesrgs::eval
