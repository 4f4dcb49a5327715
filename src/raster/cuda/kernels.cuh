#pragma once
// CUDA kernels of the rasterizer, one stage per file, each launched on the caller's stream.
#include <cuda_runtime.h>

#include "core/cuda/device_array.hpp"
#include "raster/frame.hpp"
#include "raster/rasterizer.hpp"

namespace iesrgs::raster::cuda {

using iesrgs::cuda::check;
using iesrgs::cuda::DeviceArray;

// Splats, pixel rectangles, radii and touched-tile counts of every Gaussian (culled ones get an
// empty rect, radius 0 and no tiles).
void project_forward(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                     Splat<float>* splats, PixelRect* rects, int32_t* radii,
                     uint64_t* tiles_touched, cudaStream_t stream);
// Adds the parameter gradients of every Gaussian from the per-splat gradients.
void project_backward(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                      const SplatGrad<float>* splat_grads, const GaussianGrads<float>& grads,
                      cudaStream_t stream);

// Splat-tile pairs grouped by tile, front to back inside each tile; device arrays.
struct DeviceBins {
  int tiles_x = 0, tiles_y = 0;
  const uint32_t* tile_start = nullptr;      // (tiles + 1) offsets into the sorted entries
  const uint32_t* entry_gaussian = nullptr;  // per sorted entry: its Gaussian
  size_t entries = 0;

  int tile_count() const { return tiles_x * tiles_y; }
};

// Tile binning with a device radix sort of (tile, depth) keys; owns its buffers.
class TileBinner {
 public:
  // Waits for the stream once, to size the entry arrays.
  DeviceBins bin(const Splat<float>* splats, const PixelRect* rects, const uint64_t* tiles_touched,
                 int count, int width, int height, cudaStream_t stream);

 private:
  DeviceArray<uint64_t> offsets_, keys_, sorted_keys_;
  DeviceArray<uint32_t> values_, entry_gaussian_, tile_start_;
  DeviceArray<unsigned char> scan_scratch_, sort_scratch_;
};

// Per-pixel state the forward pass leaves for the backward pass, (H * W) each.
struct PixelState {
  float* final_transmittance = nullptr;
  uint32_t* contributors = nullptr;  // entries of the pixel's tile up to its last blended splat
};

struct Background {
  float rgb[3];
};

// Front-to-back blending of every tile, one thread per pixel.
void blend_forward(const DeviceBins& bins, const Splat<float>* splats, int width, int height,
                   Background background, const RenderTargets<float>& out, PixelState state,
                   cudaStream_t stream);
// Back-to-front pass over every tile: accumulates the per-splat gradients (zeroed by the caller).
// Any of the pixel gradients may be null (zero).
void blend_backward(const DeviceBins& bins, const Splat<float>* splats, int width, int height,
                    Background background, PixelState state, const PixelGrads<float>& pixel_grads,
                    SplatGrad<float>* splat_grads, cudaStream_t stream);

constexpr int blocks_for(size_t threads, int per_block) {
  return int((threads + per_block - 1) / per_block);
}

}  // namespace iesrgs::raster::cuda
