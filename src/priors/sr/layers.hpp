#pragma once
// Building blocks shared by the super-resolution networks.
#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <string>

namespace iesrgs::priors::sr {

// A kernel x kernel convolution padded to keep the spatial size (odd kernels).
torch::nn::Conv2d same_conv(int64_t in, int64_t out, int64_t kernel, bool bias, int64_t groups = 1);

// The scale of a convolution `name` that feeds a pixel shuffle to RGB: its 3 * scale^2 output
// channels -> scale. Throws iesrgs::Error naming `file` when the count is not of that form.
int pixel_shuffle_scale(const torch::Tensor& weight, const std::string& name,
                        const std::filesystem::path& file);

// F.interpolate(x, scale_factor=factor, mode='bilinear', align_corners=False), the skip image
// several networks add to their output.
torch::Tensor upsample_bilinear(const torch::Tensor& x, int64_t factor);
// F.interpolate(x, scale_factor=factor, mode='nearest').
torch::Tensor upsample_nearest(const torch::Tensor& x, int64_t factor);

}  // namespace iesrgs::priors::sr
