#pragma once
// Tiled super-resolution: the image is upscaled in overlapping tiles and the overlaps are
// cross-faded, so memory is bounded by the output plus one tile's activations (a 1080p input
// at x4 never holds a full-resolution feature map).
#include <torch/torch.h>

#include "priors/sr/sr_net.hpp"

namespace iesrgs::priors::sr {

struct TileOptions {
  int tile = 0;  // side of a tile in input pixels; 0 upscales the whole image at once
  // Input pixels shared by neighbouring tiles. The outer quarter of an overlap is context only
  // (weight 0), the middle half is cross-faded linearly, so tiles agree with the whole-image
  // result wherever the network's receptive field stays within a quarter of the overlap. No
  // network here is that local (SAFMN and IMDN normalize by whole-input statistics, SwinIR's
  // windows shift with the tile), so tiled results differ slightly everywhere: SAFMN on a fox
  // view of 270x480 in tiles of 256 is 58.5 dB PSNR from the whole image upscaled at once.
  int overlap = 32;
};

// What upscale and the external stage use unless told otherwise: memory bounded at any image
// size, as 1080x1920 inputs need.
inline constexpr TileOptions kDefaultTiles{256, 32};

// `net`'s upscale of `rgb` (1, 3, H, W), tile by tile when options.tile is smaller than a side.
// Throws Error for an overlap that is negative or not smaller than the tile.
torch::Tensor upscale_tiled(SrNet& net, const torch::Tensor& rgb, const TileOptions& options);

}  // namespace iesrgs::priors::sr
