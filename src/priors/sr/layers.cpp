#include "priors/sr/layers.hpp"

#include <vector>

namespace iesrgs::priors::sr {

namespace F = torch::nn::functional;

namespace {

// The scale factor itself, not a size, goes to the kernel, as in the official code: the source
// coordinate of each output pixel is then computed exactly as PyTorch does there.
F::InterpolateFuncOptions by_factor(int64_t factor) {
  return F::InterpolateFuncOptions().scale_factor(
      std::vector<double>{double(factor), double(factor)});
}

}  // namespace

torch::nn::Conv2d same_conv(int64_t in, int64_t out, int64_t kernel, bool bias, int64_t groups) {
  return torch::nn::Conv2d(
      torch::nn::Conv2dOptions(in, out, kernel).padding(kernel / 2).bias(bias).groups(groups));
}

torch::Tensor upsample_bilinear(const torch::Tensor& x, int64_t factor) {
  return F::interpolate(x, by_factor(factor).mode(torch::kBilinear).align_corners(false));
}

torch::Tensor upsample_nearest(const torch::Tensor& x, int64_t factor) {
  return F::interpolate(x, by_factor(factor).mode(torch::kNearest));
}

}  // namespace iesrgs::priors::sr
