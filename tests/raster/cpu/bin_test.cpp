#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "raster/cpu/kernels.hpp"

namespace iesrgs::raster::cpu {
namespace {

struct BinCase {
  std::vector<Splat<float>> splats;
  std::vector<PixelRect> rects;
  int width, height;
};

// Random rectangles over the image, some empty; depths over several binary orders of magnitude
// with many exact ties, so that every radix digit varies and ties need the index order.
BinCase random_bin_case(int count, int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> x(0, width - 1), y(0, height - 1), extent(0, 40);
  std::uniform_real_distribution<float> depth(0.3f, 40.0f);
  BinCase c{{}, {}, width, height};
  c.splats.resize(count);
  for (int g = 0; g < count; ++g) {
    const int x0 = x(rng), y0 = y(rng);
    c.rects.push_back(g % 17 == 0 ? PixelRect{0, 0, 0, 0}
                                  : PixelRect{x0, y0, std::min(width, x0 + 1 + extent(rng)),
                                              std::min(height, y0 + 1 + extent(rng))});
    c.splats[g].depth = g % 5 == 0 && g > 0 ? c.splats[g - 5].depth : depth(rng);
  }
  return c;
}

// Every (tile, Gaussian) pair the rectangles touch, in front-to-back order with ties by index.
std::vector<std::vector<uint32_t>> expected_tiles(const BinCase& c) {
  const int tiles_x = (c.width + kTileSize - 1) / kTileSize;
  const int tiles_y = (c.height + kTileSize - 1) / kTileSize;
  std::vector<std::vector<uint32_t>> tiles(size_t(tiles_x) * tiles_y);
  for (uint32_t g = 0; g < c.rects.size(); ++g) {
    const PixelRect& r = c.rects[g];
    if (r.empty()) continue;
    for (int ty = r.y0 / kTileSize; ty <= (r.y1 - 1) / kTileSize; ++ty)
      for (int tx = r.x0 / kTileSize; tx <= (r.x1 - 1) / kTileSize; ++tx)
        tiles[size_t(ty) * tiles_x + tx].push_back(g);
  }
  for (auto& tile : tiles)
    std::stable_sort(tile.begin(), tile.end(),
                     [&](uint32_t a, uint32_t b) { return c.splats[a].depth < c.splats[b].depth; });
  return tiles;
}

void expect_binned_in_order(const BinCase& c) {
  TileBins bins;
  bin_splats(c.splats.data(), c.rects.data(), int(c.rects.size()), c.width, c.height, bins);
  const auto expected = expected_tiles(c);
  ASSERT_EQ(size_t(bins.tile_count()), expected.size());
  // The backward pass writes each entry's partial gradient to its slot: no two may share one.
  std::vector<int> slot_uses(bins.entry_slot.size(), 0);
  for (uint32_t slot : bins.entry_slot) {
    ASSERT_LT(slot, slot_uses.size());
    ++slot_uses[slot];
  }
  EXPECT_EQ(std::count(slot_uses.begin(), slot_uses.end(), 1), std::ptrdiff_t(slot_uses.size()));
  for (size_t t = 0; t < expected.size(); ++t) {
    const std::vector<uint32_t> got(bins.entry_gaussian.begin() + bins.tile_start[t],
                                    bins.entry_gaussian.begin() + bins.tile_start[t + 1]);
    ASSERT_EQ(got, expected[t]) << "tile " << t;
    // Each entry's slot lies in its Gaussian's slot range.
    for (uint32_t e = bins.tile_start[t]; e < bins.tile_start[t + 1]; ++e) {
      const uint32_t g = bins.entry_gaussian[e];
      EXPECT_GE(bins.entry_slot[e], bins.gaussian_start[g]);
      EXPECT_LT(bins.entry_slot[e], bins.gaussian_start[g + 1]);
    }
  }
}

TEST(TileBinning, SortsFewEntriesPerTileByDepthThenIndex) {
  expect_binned_in_order(random_bin_case(300, 150, 90, 1));
}

TEST(TileBinning, SortsCrowdedTilesByDepthThenIndex) {
  // Thousands of entries per tile take the radix sort.
  const BinCase c = random_bin_case(20000, 40, 40, 2);
  expect_binned_in_order(c);
  TileBins bins;
  bin_splats(c.splats.data(), c.rects.data(), int(c.rects.size()), c.width, c.height, bins);
  EXPECT_GT(bins.tile_start[1] - bins.tile_start[0], 1000u);
}

TEST(TileBinning, EqualDepthsKeepIndexOrder) {
  BinCase c = random_bin_case(3000, 16, 16, 3);
  for (auto& s : c.splats) s.depth = 2.5f;
  expect_binned_in_order(c);
}

}  // namespace
}  // namespace iesrgs::raster::cpu
