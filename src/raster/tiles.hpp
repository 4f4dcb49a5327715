#pragma once
// Which 16x16 tiles a splat's pixel rectangle touches, and the depth half of the sort key that
// orders a tile's splats front to back; shared by the CPU and CUDA binning.
#include <cstdint>
#include <cstring>

#include "raster/types.hpp"

namespace iesrgs::raster {

// Half-open tile rectangle [x0, x1) x [y0, y1).
struct TileRect {
  int x0, y0, x1, y1;

  IESRGS_HD uint32_t count() const { return uint32_t(x1 - x0) * uint32_t(y1 - y0); }
};

IESRGS_HD TileRect tiles_of(const PixelRect& r) {
  if (r.empty()) return {0, 0, 0, 0};
  return {r.x0 / kTileSize, r.y0 / kTileSize, (r.x1 - 1) / kTileSize + 1,
          (r.y1 - 1) / kTileSize + 1};
}

// Camera z is above the near plane, hence positive: the IEEE bits of a positive float sort like
// its value.
IESRGS_HD uint32_t depth_bits(float depth) {
#if defined(__CUDA_ARCH__)
  return __float_as_uint(depth);
#else
  uint32_t bits;
  std::memcpy(&bits, &depth, sizeof bits);
  return bits;
#endif
}

}  // namespace iesrgs::raster
