// Per-tile alpha blending. The loops run splat-major: each splat of a tile (front to back in the
// forward pass, back to front in the backward pass) visits only the pixels its cut-off ellipse
// covers, a SIMD pack at a time, with the per-pixel state of the tile in structure-of-arrays
// buffers laid out in blocks of a few rows, one pack each. The backward pass recomputes each
// splat's alphas instead of storing per-pixel lists.
// Compiled once per instruction-set variant (core/cpu_isa_variant.hpp), each into its own
// namespace.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "raster/cpu/pack.hpp"
#include "raster/cpu/variants.hpp"

namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE {

namespace {

// A tile's pixel window in the image and a splat's rectangle clipped to it.
struct TileWindow {
  int x0, y0, x1, y1;

  TileWindow clip(const PixelRect& r) const {
    return {std::max(x0, r.x0), std::max(y0, r.y0), std::min(x1, r.x1), std::min(y1, r.y1)};
  }
};

// The tile's pixel state is stored in blocks of kBlockRows rows by kBlockColumns columns, one
// pack each (4 x 2 pixels for AVX2 floats, 4 x 1 for SSE2). Most splats span a few pixels each
// way: a pack per row would mostly hold pixels outside their ellipse. Four rows measured faster
// than two or eight on trained lego models at 100x100 and 400x400.
template <typename T>
constexpr int kBlockRows = std::min(kLanes<T>, 4);
template <typename T>
constexpr int kBlockColumns = kLanes<T> / kBlockRows<T>;

// Where pixel (x, y) of the tile window lies in the block layout.
template <typename T>
int pixel_index(const TileWindow& win, int x, int y) {
  constexpr int rows = kBlockRows<T>, columns = kBlockColumns<T>;
  const int dx = x - win.x0, dy = y - win.y0;
  const int block = (dy / rows) * (kTileSize / columns) + dx / columns;
  return block * kLanes<T> + (dy % rows) * columns + dx % columns;
}

// Offsets of the lanes' pixel centers from a block's top left corner.
template <typename T>
Pack<T> lane_columns() {
  Pack<T> v;
  for (int i = 0; i < kLanes<T>; ++i) v[i] = T(i % kBlockColumns<T>) + T(0.5);
  return v;
}

template <typename T>
Pack<T> lane_rows() {
  Pack<T> v;
  for (int i = 0; i < kLanes<T>; ++i) v[i] = T(i / kBlockColumns<T>) + T(0.5);
  return v;
}

// Entries name splats in depth order, i.e. at random places in memory: fetch ahead.
constexpr uint32_t kPrefetchDistance = 4;

template <typename T>
void prefetch_splat(const RasterFrame<T>& frame, uint32_t entry) {
  const uint32_t g = frame.bins.entry_gaussian[entry];
  __builtin_prefetch(&frame.splats[g]);
  __builtin_prefetch(&frame.rects[g]);
}

TileWindow tile_window(const TileBins& bins, int tile, int width, int height) {
  const int x0 = (tile % bins.tiles_x) * kTileSize, y0 = (tile / bins.tiles_x) * kTileSize;
  return {x0, y0, std::min(x0 + kTileSize, width), std::min(y0 + kTileSize, height)};
}

// Block row by block row, the columns where a splat can reach alpha 1/255: the chords of its
// cut-off ellipse xx dx^2 + 2 xy dx dy + yy dy^2 <= cutoff (dx, dy: mean minus pixel center),
// clipped to `box` (the splat's rectangle within the tile window), joined over the block's rows
// and widened to whole blocks so that the pixel loops run on full vectors. The extra pixels lie
// outside the ellipse, where the alpha test rejects them, or off the image, where the pixel
// state keeps them inert.
template <typename T>
class Chords {
 public:
  Chords(const Splat<T>& s, const TileWindow& win, const TileWindow& box)
      : s_(s),
        win_(win),
        box_(box),
        inv_xx_(T(1) / s.conic_xx),
        slope_(s.conic_xy * inv_xx_),
        reach_(s.conic_xx * s.cutoff) {}

  // The `blocks` blocks from column x on of the block row starting at row y (a multiple of
  // kBlockRows from the window's top); false when its rows miss the ellipse.
  bool block_row(int y, int& x, int& blocks) const {
    int lo = box_.x1, hi = box_.x0;
    for (int r = std::max(y, box_.y0); r < std::min(y + kBlockRows<T>, box_.y1); ++r)
      widen(r, lo, hi);
    if (lo >= hi) return false;
    constexpr int columns = kBlockColumns<T>;
    x = win_.x0 + (lo - win_.x0) / columns * columns;
    blocks = (hi - x + columns - 1) / columns;
    return true;
  }

 private:
  // Widens [lo, hi) to the chord of row y, if any.
  void widen(int y, int& lo, int& hi) const {
    const T dy = s_.y - (T(y) + T(0.5));
    const T quarter_disc = reach_ - dy * dy * s_.conic_det;
    if (!(quarter_disc > T(0))) return;
    const T center = s_.x + slope_ * dy;
    // Half a pixel of slack covers rounding in the chord.
    const T half = std::sqrt(quarter_disc) * inv_xx_ + T(0.5);
    // Pixel i is inside when its center i + 0.5 is; the box keeps both ends non-negative, so
    // integer conversion is floor.
    const T first = clamp(center - half - T(0.5)), end = clamp(center + half + T(0.5));
    int first_column = int(first);
    first_column += T(first_column) < first;
    const int end_column = int(end);
    if (first_column >= end_column) return;
    lo = std::min(lo, first_column);
    hi = std::max(hi, end_column);
  }

  T clamp(T v) const { return std::min(T(box_.x1), std::max(T(box_.x0), v)); }

  const Splat<T>& s_;
  TileWindow win_, box_;
  T inv_xx_, slope_, reach_;
};

// `blocks` consecutive blocks of one block row, the first with its top left pixel at (x, y) and
// its state at index p.
struct BlockRun {
  int x, y, p, blocks;
};

// Calls visit(run) for each block row of the splat's box that its ellipse reaches.
template <typename T, typename Visit>
void for_each_block_run(const Splat<T>& s, const TileWindow& win, const TileWindow& box,
                        Visit visit) {
  const Chords<T> chords(s, win, box);
  int x, blocks;
  for (int y = box.y0 - (box.y0 - win.y0) % kBlockRows<T>; y < box.y1; y += kBlockRows<T>)
    if (chords.block_row(y, x, blocks)) visit(BlockRun{x, y, pixel_index<T>(win, x, y), blocks});
}

template <typename T>
struct alignas(64) ForwardPixels {
  T transmittance[kTilePixels];
  T color[3][kTilePixels];
  T depth[kTilePixels];
  T live[kTilePixels];  // 1 until the pixel reaches the transmittance cut-off, then 0
  uint32_t contributors[kTilePixels];
};

// Blends splat s (entry number `entry` of its tile) into the pixels of a run of blocks. Returns
// how many pixels reached the cut-off.
template <typename T>
int blend_blocks(const Splat<T>& s, uint32_t entry, BlockRun run, ForwardPixels<T>& px) {
  const Pack<T> dy = s.y - (T(run.y) + lane_rows<T>());
  const Index<T> contributor = Index<T>{} + (entry + 1);
  int stopped = 0;
  for (int b = 0, i = run.p, x = run.x; b < run.blocks;
       ++b, i += kLanes<T>, x += kBlockColumns<T>) {
    const Pack<T> dx = s.x - (T(x) + lane_columns<T>());
    const Pack<T> power = splat_power(s, dx, dy);
    const Pack<T> a = load(px.live + i) * splat_alpha<T>(power, s.opacity * falloff_exp<T>(power));
    const Pack<T> trans = load(px.transmittance + i);
    const Pack<T> next = trans * (T(1) - a);
    // 3DGS stops a pixel before blending the splat that would drop it below the cut-off.
    // Where a == 0 nothing changes: next == trans and the weight is 0.
    const Mask<T> stop = (a > T(0)) & (next < T(kMinTransmittance));
    const Pack<T> w = select<T>(stop, Pack<T>{}, a * trans);
    for (int c = 0; c < 3; ++c) store(px.color[c] + i, load(px.color[c] + i) + w * s.color[c]);
    store(px.depth + i, load(px.depth + i) + w * s.depth);
    store(px.transmittance + i, select<T>(stop, trans, next));
    store_index<T>(px.contributors + i,
                   (w > T(0)) ? contributor : load_index<T>(px.contributors + i));
    store(px.live + i, select<T>(stop, Pack<T>{}, load(px.live + i)));
    stopped += count<T>(stop);
  }
  return stopped;
}

template <typename T>
void blend_tile_forward(RasterFrame<T>& frame, int tile, T* image, T* alpha, T* depth) {
  const RasterCamera<T>& cam = frame.camera;
  const TileBins& bins = frame.bins;
  const TileWindow win = tile_window(bins, tile, cam.width, cam.height);
  ForwardPixels<T> px;
  std::fill_n(px.transmittance, kTilePixels, T(1));
  std::fill_n(&px.color[0][0], 3 * kTilePixels, T(0));
  std::fill_n(px.depth, kTilePixels, T(0));
  // Pixels off the image (in border tiles) never blend.
  std::fill_n(px.live, kTilePixels, T(0));
  for (int y = win.y0; y < win.y1; ++y)
    for (int x = win.x0; x < win.x1; ++x) px.live[pixel_index<T>(win, x, y)] = T(1);
  std::fill_n(px.contributors, kTilePixels, 0u);
  int active = (win.x1 - win.x0) * (win.y1 - win.y0);

  const uint32_t begin = bins.tile_start[tile], end = bins.tile_start[tile + 1];
  for (uint32_t e = begin; e < end && active > 0; ++e) {
    if (e + kPrefetchDistance < end) prefetch_splat(frame, e + kPrefetchDistance);
    const uint32_t g = bins.entry_gaussian[e];
    const Splat<T>& s = frame.splats[g];
    for_each_block_run(s, win, win.clip(frame.rects[g]),
                       [&](const BlockRun& run) { active -= blend_blocks(s, e - begin, run, px); });
  }

  const size_t plane = size_t(cam.width) * cam.height;
  for (int y = win.y0; y < win.y1; ++y)
    for (int x = win.x0; x < win.x1; ++x) {
      const int p = pixel_index<T>(win, x, y);
      const size_t i = size_t(y) * cam.width + x;
      for (int c = 0; c < 3; ++c)
        image[c * plane + i] = px.color[c][p] + px.transmittance[p] * frame.background[c];
      alpha[i] = T(1) - px.transmittance[p];
      depth[i] = px.depth[p];
      frame.final_transmittance[i] = px.transmittance[p];
      frame.contributors[i] = px.contributors[p];
    }
}

// Backward per-pixel state. The color and depth gradients are constant per pixel, so what a
// splat hides only matters through its loss-weighted value: behind = dL/dcolor . color_behind +
// dL/ddepth . depth_behind, blended back to front like the colors themselves.
template <typename T>
struct alignas(64) BackwardPixels {
  T transmittance[kTilePixels];  // in front of the current splat
  uint32_t contributors[kTilePixels];
  T dcolor[3][kTilePixels];
  T ddepth[kTilePixels];
  // final transmittance x (d(alpha output) - background . d(color)): how the loss moves with
  // the light that passes every splat.
  T dfinal[kTilePixels];
  T behind[kTilePixels];
};

template <typename T>
uint32_t load_backward_pixels(const RasterFrame<T>& frame, const TileWindow& win, const T* dimage,
                              const T* dalpha, const T* ddepth, BackwardPixels<T>& px) {
  const RasterCamera<T>& cam = frame.camera;
  const size_t plane = size_t(cam.width) * cam.height;
  uint32_t last = 0;
  for (int y = win.y0; y < win.y1; ++y)
    for (int x = win.x0; x < win.x1; ++x) {
      const int p = pixel_index<T>(win, x, y);
      const size_t i = size_t(y) * cam.width + x;
      px.transmittance[p] = frame.final_transmittance[i];
      px.contributors[p] = frame.contributors[i];
      last = std::max(last, px.contributors[p]);
      T dfinal = dalpha ? dalpha[i] : T(0);
      for (int c = 0; c < 3; ++c) {
        px.dcolor[c][p] = dimage ? dimage[c * plane + i] : T(0);
        dfinal -= frame.background[c] * px.dcolor[c][p];
      }
      px.dfinal[p] = frame.final_transmittance[i] * dfinal;
      px.ddepth[p] = ddepth ? ddepth[i] : T(0);
      px.behind[p] = T(0);
    }
  return last;
}

// A splat's gradient summed lane-wise over its pixels, in SplatGrad's field order; reduced across
// lanes once per splat.
template <typename T>
struct PackedGrad {
  Pack<T> x{}, y{}, conic_xx{}, conic_xy{}, conic_yy{}, opacity{};
  Pack<T> color[3] = {};
  Pack<T> depth{}, abs_x{}, abs_y{};

  SplatGrad<T> sum() const {
    static constexpr int kFields = SplatGrad<T>::kFields;
    static_assert(sizeof(PackedGrad) == kFields * sizeof(Pack<T>));
    Pack<T> fields[kFields];
    std::memcpy(fields, this, sizeof fields);
    SplatGrad<T> g;
    T sums[kFields];
    horizontal_sums(fields, sums);
    std::memcpy(&g, sums, sizeof g);
    return g;
  }
};

// Adds to acc the gradient of the pixels of a run of blocks with respect to splat s (entry number
// `entry` of its tile), and moves their state in front of s. Pixels that did not blend s get
// alpha 0, which leaves their state unchanged and adds nothing.
template <typename T>
void backward_blocks(const Splat<T>& s, uint32_t entry, BlockRun run, BackwardPixels<T>& px,
                     PackedGrad<T>& acc) {
  const Pack<T> dy = s.y - (T(run.y) + lane_rows<T>());
  const Index<T> entries = Index<T>{} + entry;
  for (int b = 0, i = run.p, x = run.x; b < run.blocks;
       ++b, i += kLanes<T>, x += kBlockColumns<T>) {
    const Pack<T> dx = s.x - (T(x) + lane_columns<T>());
    const Pack<T> power = splat_power(s, dx, dy);
    const Pack<T> falloff = falloff_exp<T>(power);
    const Pack<T> weight = s.opacity * falloff;
    const Pack<T> a = select<T>(entries < load_index<T>(px.contributors + i),
                                splat_alpha<T>(power, weight), Pack<T>{});
    const Pack<T> inv_opaque = T(1) / (T(1) - a);
    const Pack<T> t_front = load(px.transmittance + i) * inv_opaque;
    const Pack<T> w = a * t_front;
    // The splat's own loss-weighted color and depth.
    Pack<T> value = s.depth * load(px.ddepth + i);
    acc.depth += w * load(px.ddepth + i);
    for (int c = 0; c < 3; ++c) {
      const Pack<T> dcolor = load(px.dcolor[c] + i);
      acc.color[c] += w * dcolor;
      value += s.color[c] * dcolor;
    }
    // d(loss)/d(alpha): the splat's value minus what it hides, and the final transmittance
    // (alpha output and background) shrinking with every blended alpha.
    const Pack<T> behind = load(px.behind + i);
    const Pack<T> da = t_front * (value - behind) + inv_opaque * load(px.dfinal + i);
    store(px.behind + i, a * value + (T(1) - a) * behind);
    store(px.transmittance + i, t_front);
    // Alpha capped at 0.99 passes no gradient to opacity or shape: the derivative of the cap, as
    // gsplat takes it (3DGS's kernel passes the uncapped alpha's).
    const Pack<T> da_live = select<T>((a > T(0)) & (weight <= T(kMaxAlpha)), da, Pack<T>{});
    acc.opacity += da_live * falloff;
    const Pack<T> dpower = a * da_live;
    const Pack<T> dmx = -dpower * (s.conic_xx * dx + s.conic_xy * dy);
    const Pack<T> dmy = -dpower * (s.conic_yy * dy + s.conic_xy * dx);
    acc.x += dmx;
    acc.y += dmy;
    acc.abs_x += abs<T>(dmx);
    acc.abs_y += abs<T>(dmy);
    acc.conic_xx += T(-0.5) * dx * dx * dpower;
    acc.conic_xy += -dx * dy * dpower;
    acc.conic_yy += T(-0.5) * dy * dy * dpower;
  }
}

template <typename T>
void blend_tile_backward(RasterFrame<T>& frame, int tile, const T* dimage, const T* dalpha,
                         const T* ddepth) {
  const TileBins& bins = frame.bins;
  const TileWindow win = tile_window(bins, tile, frame.camera.width, frame.camera.height);
  BackwardPixels<T> px{};  // zero, so that pixels off the image stay inert
  const uint32_t last = load_backward_pixels(frame, win, dimage, dalpha, ddepth, px);
  const uint32_t begin = bins.tile_start[tile], end = bins.tile_start[tile + 1];
  // Entries no pixel blended get zero partials.
  for (uint32_t e = begin + last; e < end; ++e) frame.entry_grads[bins.entry_slot[e]] = {};
  for (uint32_t k = last; k-- > 0;) {
    if (k >= kPrefetchDistance) prefetch_splat(frame, begin + k - kPrefetchDistance);
    const uint32_t g = bins.entry_gaussian[begin + k];
    PackedGrad<T> acc;
    const Splat<T>& s = frame.splats[g];
    for_each_block_run(s, win, win.clip(frame.rects[g]),
                       [&](const BlockRun& run) { backward_blocks(s, k, run, px, acc); });
    frame.entry_grads[bins.entry_slot[begin + k]] = acc.sum();
  }
}

// Sums each Gaussian's per-entry partials, which sit in its contiguous slots.
template <typename T>
void reduce_entry_grads(RasterFrame<T>& frame) {
  const int count = int(frame.splats.size());
  const auto& start = frame.bins.gaussian_start;
#pragma omp parallel for schedule(static)
  for (int g = 0; g < count; ++g) {
    SplatGrad<T> sum{};
    for (uint64_t s = start[g]; s < start[g + 1]; ++s) sum += frame.entry_grads[s];
    frame.splat_grads[g] = sum;
  }
}

template <typename T>
void forward_pass(RasterFrame<T>& frame, T* image, T* alpha, T* depth) {
#pragma omp parallel for schedule(dynamic, 1)
  for (int t = 0; t < frame.bins.tile_count(); ++t)
    blend_tile_forward(frame, t, image, alpha, depth);
}

template <typename T>
void backward_pass(RasterFrame<T>& frame, const T* dimage, const T* dalpha, const T* ddepth) {
#pragma omp parallel for schedule(dynamic, 1)
  for (int t = 0; t < frame.bins.tile_count(); ++t)
    blend_tile_backward(frame, t, dimage, dalpha, ddepth);
  reduce_entry_grads(frame);
}

}  // namespace

template <typename T>
BlendPasses<T> blend_passes() {
  return {forward_pass<T>, backward_pass<T>, kPackBytes};
}

template BlendPasses<float> blend_passes();
template BlendPasses<double> blend_passes();

}  // namespace iesrgs::raster::cpu::IESRGS_CPU_ISA_NAMESPACE
