#pragma once
// A false-color picture of a depth map, for people to look at.
#include <torch/torch.h>

#include "io/image.hpp"

namespace iesrgs::priors::depth {

// (H, W) float map -> RGB, min-max normalized onto a perceptually ordered ramp from near-black
// (smallest value) through purple, red and orange to pale yellow (largest), so that nearer
// surfaces of an inverse-depth map come out brighter. A constant map is all near-black.
// Throws Error for anything but a non-empty 2-D tensor.
Image8 depth_preview(const torch::Tensor& depth);

}  // namespace iesrgs::priors::depth
