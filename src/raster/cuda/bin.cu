// Tile binning on the GPU: an inclusive scan of the touched-tile counts gives each Gaussian its
// slots, every slot gets the key (tile << 32 | depth bits), and one stable radix sort groups the
// keys by tile and orders each tile front to back. Slots are written in Gaussian order, so depth
// ties are broken by Gaussian index, as on the CPU.
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include "raster/cuda/kernels.cuh"
#include "raster/tiles.hpp"

namespace iesrgs::raster::cuda {

namespace {

constexpr int kThreads = 256;

__global__ void write_keys_kernel(int count, const Splat<float>* splats, const PixelRect* rects,
                                  const uint64_t* slot_end, int tiles_x, uint64_t* keys,
                                  uint32_t* gaussians) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= count) return;
  const TileRect t = tiles_of(rects[i]);
  if (t.count() == 0) return;
  uint32_t slot = uint32_t(i == 0 ? 0 : slot_end[i - 1]);
  const uint64_t depth = depth_bits(splats[i].depth);
  for (int ty = t.y0; ty < t.y1; ++ty)
    for (int tx = t.x0; tx < t.x1; ++tx, ++slot) {
      keys[slot] = uint64_t(ty * tiles_x + tx) << 32 | depth;
      gaussians[slot] = uint32_t(i);
    }
}

// tile_start[t] = the first sorted entry whose tile is t or later.
__global__ void tile_starts_kernel(uint32_t entries, const uint64_t* keys, int tiles,
                                   uint32_t* tile_start) {
  const uint32_t e = blockIdx.x * blockDim.x + threadIdx.x;
  if (e >= entries) return;
  const int tile = int(keys[e] >> 32);
  const int previous = e == 0 ? -1 : int(keys[e - 1] >> 32);
  for (int t = previous + 1; t <= tile; ++t) tile_start[t] = e;
  if (e + 1 == entries)
    for (int t = tile + 1; t <= tiles; ++t) tile_start[t] = entries;
}

int bit_width(uint32_t v) {
  int bits = 0;
  while (v >> bits) ++bits;
  return bits;
}

}  // namespace

DeviceBins TileBinner::bin(const Splat<float>* splats, const PixelRect* rects,
                           const uint64_t* tiles_touched, int count, int width, int height,
                           cudaStream_t stream) {
  DeviceBins bins;
  bins.tiles_x = (width + kTileSize - 1) / kTileSize;
  bins.tiles_y = (height + kTileSize - 1) / kTileSize;
  const int tiles = bins.tile_count();
  uint32_t* tile_start = tile_start_.reserve(size_t(tiles) + 1);
  bins.tile_start = tile_start;
  uint64_t total = 0;
  if (count > 0) {
    uint64_t* slot_end = offsets_.reserve(count);
    size_t scratch = 0;
    check(cub::DeviceScan::InclusiveSum(nullptr, scratch, tiles_touched, slot_end, count, stream),
          "scan size");
    check(cub::DeviceScan::InclusiveSum(scan_scratch_.reserve(scratch), scratch, tiles_touched,
                                        slot_end, count, stream),
          "scan");
    check(
        cudaMemcpyAsync(&total, slot_end + count - 1, sizeof total, cudaMemcpyDeviceToHost, stream),
        "copy of the entry count");
    check(cudaStreamSynchronize(stream), "binning");
  }
  // Entries are indexed with 32 bits, as on the CPU.
  if (total >= (uint64_t(1) << 32))
    fail("rasterizer: {} splat-tile pairs exceed the 2^32 limit", total);
  const uint32_t entries = uint32_t(total);
  bins.entries = entries;
  if (entries == 0) {
    check(cudaMemsetAsync(tile_start, 0, (size_t(tiles) + 1) * sizeof(uint32_t), stream),
          "clearing the tile ranges");
    return bins;
  }
  uint64_t* keys = keys_.reserve(entries);
  uint32_t* gaussians = values_.reserve(entries);
  write_keys_kernel<<<blocks_for(count, kThreads), kThreads, 0, stream>>>(
      count, splats, rects, offsets_.data(), bins.tiles_x, keys, gaussians);
  check(cudaGetLastError(), "write_keys");

  uint64_t* sorted_keys = sorted_keys_.reserve(entries);
  uint32_t* entry_gaussian = entry_gaussian_.reserve(entries);
  const int end_bit = 32 + bit_width(uint32_t(tiles - 1));
  size_t scratch = 0;
  check(cub::DeviceRadixSort::SortPairs(nullptr, scratch, keys, sorted_keys, gaussians,
                                        entry_gaussian, entries, 0, end_bit, stream),
        "sort size");
  check(cub::DeviceRadixSort::SortPairs(sort_scratch_.reserve(scratch), scratch, keys, sorted_keys,
                                        gaussians, entry_gaussian, entries, 0, end_bit, stream),
        "sort");
  tile_starts_kernel<<<blocks_for(entries, kThreads), kThreads, 0, stream>>>(entries, sorted_keys,
                                                                             tiles, tile_start);
  check(cudaGetLastError(), "tile_starts");
  bins.entry_gaussian = entry_gaussian;
  return bins;
}

}  // namespace iesrgs::raster::cuda
