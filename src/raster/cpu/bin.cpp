// Tile binning: a counting sort of splat-tile entries by tile, then a depth sort inside each tile.
// Per-tile sorts are small and independent, so they run in parallel and stay in cache, unlike
// one global sort by a (tile, depth) key; the order is the same.
#include <algorithm>

#include "core/error.hpp"
#include "raster/cpu/kernels.hpp"
#include "raster/tiles.hpp"

namespace iesrgs::raster::cpu {

namespace {

// Gaussian-major slot offsets: Gaussian g owns [start[g], start[g + 1]).
void count_slots(const PixelRect* rects, int count, TileBins& bins) {
  bins.gaussian_start.assign(size_t(count) + 1, 0);
  for (int g = 0; g < count; ++g) {
    const TileRect t = tiles_of(rects[g]);
    bins.gaussian_start[g + 1] = bins.gaussian_start[g] + t.count();
  }
  // Slots are stored as 32-bit indices.
  if (bins.gaussian_start[count] >= (uint64_t(1) << 32))
    fail("rasterizer: {} splat-tile pairs exceed the 2^32 limit", bins.gaussian_start[count]);
}

void fill_slots(const PixelRect* rects, int count, TileBins& bins) {
  const size_t entries = bins.gaussian_start[count];
  bins.slot_gaussian.resize(entries);
  bins.slot_tile.resize(entries);
#pragma omp parallel for schedule(dynamic, 256)
  for (int g = 0; g < count; ++g) {
    const TileRect t = tiles_of(rects[g]);
    uint64_t slot = bins.gaussian_start[g];
    for (int ty = t.y0; ty < t.y1; ++ty)
      for (int tx = t.x0; tx < t.x1; ++tx, ++slot) {
        bins.slot_gaussian[slot] = uint32_t(g);
        bins.slot_tile[slot] = uint32_t(ty * bins.tiles_x + tx);
      }
  }
}

template <typename T>
void group_by_tile(const Splat<T>* splats, TileBins& bins) {
  const size_t entries = bins.slot_tile.size();
  bins.tile_start.assign(size_t(bins.tile_count()) + 1, 0);
  for (size_t s = 0; s < entries; ++s) ++bins.tile_start[bins.slot_tile[s] + 1];
  for (int t = 0; t < bins.tile_count(); ++t) bins.tile_start[t + 1] += bins.tile_start[t];
  std::vector<uint32_t> cursor(bins.tile_start.begin(), bins.tile_start.end() - 1);
  bins.keys.resize(entries);
  for (size_t s = 0; s < entries; ++s) {
    const uint32_t g = bins.slot_gaussian[s];
    // Ties in depth are broken by the slot, i.e. by Gaussian index.
    bins.keys[cursor[bins.slot_tile[s]]++] = uint64_t(depth_bits(float(splats[g].depth))) << 32 | s;
  }
}

// Stable LSD radix sort of a tile's keys by their depth half, 8 bits per pass. group_by_tile
// wrote them in slot order, so stability breaks depth ties by slot as a full-key sort would.
// A pass whose digit is the same for every key is skipped: depths within a factor of two share
// their top byte. Returns the buffer that holds the sorted keys.
uint64_t* radix_sort_by_depth(uint64_t* keys, uint64_t* scratch, uint32_t n) {
  constexpr int kPasses = 4;
  uint32_t counts[kPasses][256] = {};
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t depth = uint32_t(keys[i] >> 32);
    for (int p = 0; p < kPasses; ++p) ++counts[p][depth >> (8 * p) & 255];
  }
  uint64_t *src = keys, *dst = scratch;
  for (int p = 0; p < kPasses; ++p) {
    const int shift = 32 + 8 * p;
    if (counts[p][src[0] >> shift & 255] == n) continue;
    uint32_t offset[256], sum = 0;
    for (int d = 0; d < 256; ++d) offset[d] = sum, sum += counts[p][d];
    for (uint32_t i = 0; i < n; ++i) dst[offset[src[i] >> shift & 255]++] = src[i];
    std::swap(src, dst);
  }
  return src;
}

// Below this many keys the histograms cost more than a comparison sort.
constexpr uint32_t kRadixSortMinKeys = 256;

void sort_tiles(TileBins& bins) {
  bins.entry_gaussian.resize(bins.keys.size());
  bins.entry_slot.resize(bins.keys.size());
  bins.sort_scratch.resize(bins.keys.size());
#pragma omp parallel for schedule(dynamic, 4)
  for (int t = 0; t < bins.tile_count(); ++t) {
    const uint32_t begin = bins.tile_start[t], end = bins.tile_start[t + 1];
    uint64_t* sorted = bins.keys.data() + begin;
    if (end - begin >= kRadixSortMinKeys)
      sorted = radix_sort_by_depth(sorted, bins.sort_scratch.data() + begin, end - begin);
    else
      std::sort(sorted, sorted + (end - begin));
    for (uint32_t e = begin; e < end; ++e) {
      const uint32_t slot = uint32_t(sorted[e - begin]);
      bins.entry_slot[e] = slot;
      bins.entry_gaussian[e] = bins.slot_gaussian[slot];
    }
  }
}

}  // namespace

template <typename T>
void bin_splats(const Splat<T>* splats, const PixelRect* rects, int count, int width, int height,
                TileBins& bins) {
  bins.tiles_x = (width + kTileSize - 1) / kTileSize;
  bins.tiles_y = (height + kTileSize - 1) / kTileSize;
  count_slots(rects, count, bins);
  fill_slots(rects, count, bins);
  group_by_tile(splats, bins);
  sort_tiles(bins);
}

template void bin_splats(const Splat<float>*, const PixelRect*, int, int, int, TileBins&);
template void bin_splats(const Splat<double>*, const PixelRect*, int, int, int, TileBins&);

}  // namespace iesrgs::raster::cpu
