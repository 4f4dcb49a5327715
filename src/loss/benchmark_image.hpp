#pragma once
// A fixed image for timing the loss kernels, shared by iesrgs_bench and `iesrgs bench ssim`:
// content does not change their cost, and a fixed pattern keeps runs comparable.
#include <cstdint>
#include <vector>

#include "loss/image_shape.hpp"

namespace iesrgs::loss {

inline std::vector<float> benchmark_image(const ImageShape& shape, uint32_t seed) {
  std::vector<float> image(shape.values());
  for (size_t i = 0; i < image.size(); ++i)
    image[i] = float((uint32_t(i + seed) * 2654435761u) >> 8) / 16777216.f;  // 24 bits: [0, 1)
  return image;
}

}  // namespace iesrgs::loss
