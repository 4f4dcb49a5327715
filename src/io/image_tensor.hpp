#pragma once
// Conversions between the project's interleaved images and the planar (1, 3, H, W) float
// tensors the super-resolution networks take, plus the check every backend applies to its input.
#include <torch/torch.h>

#include <string>

#include "io/image.hpp"

namespace iesrgs {

// RGB image -> (1, 3, H, W) float32, contiguous. Throws Error unless it has 3 channels.
torch::Tensor to_tensor(const Image& rgb);
// (1, 3, H, W) float -> RGB image, values as they are (no clamping).
Image to_image(const torch::Tensor& rgb);
// (1, 3, H, W) float in [0, 1] -> 8-bit RGB, rounded and clamped like to_8bit.
Image8 to_image8(const torch::Tensor& rgb);

// Throws Error("<model>: ...") unless `rgb` is a float32 CPU tensor of shape (1, 3, H, W).
void check_rgb_batch(const torch::Tensor& rgb, const std::string& model);

}  // namespace iesrgs
