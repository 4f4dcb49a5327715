#pragma once
// Host-side state of one rendered frame: what the forward pass computes and the backward pass
// reuses. Buffers keep their capacity, so rendering many frames with one RasterFrame allocates
// only while scenes grow.
#include <cstdint>
#include <vector>

#include "raster/types.hpp"

namespace iesrgs::raster {

// Splat-tile pairs ("entries") grouped by tile and sorted front to back inside each tile.
struct TileBins {
  int tiles_x = 0, tiles_y = 0;
  std::vector<uint32_t> tile_start;      // (tiles + 1) offsets into the sorted entries
  std::vector<uint32_t> entry_gaussian;  // per sorted entry: its Gaussian
  // Per sorted entry: its slot in Gaussian-major order, where Gaussian g owns the slots
  // [gaussian_start[g], gaussian_start[g + 1]); the backward pass writes per-entry partial
  // gradients there and reduces each Gaussian's contiguous slots without races.
  std::vector<uint32_t> entry_slot;
  std::vector<uint64_t> gaussian_start;  // (N + 1)
  // Scratch reused between frames.
  std::vector<uint32_t> slot_gaussian, slot_tile;
  std::vector<uint64_t> keys, sort_scratch;

  int tile_count() const { return tiles_x * tiles_y; }
  size_t entry_count() const { return entry_gaussian.size(); }
};

// Milliseconds spent in each stage of the latest forward / backward call.
struct RasterTimings {
  double project = 0, bin = 0, blend = 0;           // forward
  double blend_backward = 0, project_backward = 0;  // backward
};

template <typename T>
struct RasterFrame {
  RasterCamera<T> camera;
  T background[3] = {0, 0, 0};
  std::vector<Splat<T>> splats;  // (N)
  std::vector<PixelRect> rects;  // (N), empty for culled Gaussians
  TileBins bins;
  std::vector<T> final_transmittance;  // (H * W)
  std::vector<uint32_t> contributors;  // (H * W) entries of its tile up to its last blended splat
  std::vector<SplatGrad<T>> entry_grads;  // (entries), by slot
  std::vector<SplatGrad<T>> splat_grads;  // (N)
  RasterTimings timings;
};

}  // namespace iesrgs::raster
