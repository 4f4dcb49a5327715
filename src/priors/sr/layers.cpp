#include "priors/sr/layers.hpp"

#include <fmt/format.h>

#include <cmath>
#include <vector>

#include "core/error.hpp"

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

int pixel_shuffle_scale(const torch::Tensor& weight, const std::string& name,
                        const std::filesystem::path& file) {
  const int64_t channels = weight.size(0);
  const auto scale = int(std::lround(std::sqrt(double(channels) / 3)));
  if (scale < 1 || 3 * int64_t(scale) * scale != channels)
    fail_file(file, fmt::format("{} has {} output channels, not 3 * scale^2", name, channels));
  return scale;
}

torch::Tensor upsample_bilinear(const torch::Tensor& x, int64_t factor) {
  return F::interpolate(x, by_factor(factor).mode(torch::kBilinear).align_corners(false));
}

torch::Tensor upsample_nearest(const torch::Tensor& x, int64_t factor) {
  return F::interpolate(x, by_factor(factor).mode(torch::kNearest));
}

}  // namespace iesrgs::priors::sr
