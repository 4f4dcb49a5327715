#pragma once
// Size of the images the loss kernels take: raw planar CHW arrays (channel c of pixel p at
// data[c * pixels + p]), the layout the rasterizer renders and 3DGS's tensors use.
#include <cstddef>

#include "core/error.hpp"
#include "core/hd.hpp"

namespace iesrgs::loss {

struct ImageShape {
  int width = 0, height = 0, channels = 0;

  IESRGS_HD size_t pixels() const { return size_t(width) * size_t(height); }
  IESRGS_HD size_t values() const { return pixels() * size_t(channels); }
};

// Throws Error("<what>: ...") for an empty or negative size.
inline void check_shape(const ImageShape& shape, const char* what) {
  if (shape.width <= 0 || shape.height <= 0 || shape.channels <= 0)
    fail("{}: image size {}x{}x{} is empty", what, shape.width, shape.height, shape.channels);
}

}  // namespace iesrgs::loss
