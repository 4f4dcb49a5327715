#include "loss/ssim.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <type_traits>
#include <vector>

#include "core/cpu_isa.hpp"
#include "loss/ssim_point.hpp"
#include "loss/ssim_rows.hpp"

namespace iesrgs::loss {
namespace {

constexpr int kRadius = kSsimWindow / 2;
constexpr int kMomentPlanes = 4;  // MomentRows

// The window's taps in the kernels' scalar type.
template <typename T>
struct Window {
  T tap[kSsimWindow];

  Window() {
    const auto weight = ssim_window();
    for (int k = 0; k < kSsimWindow; ++k) tap[k] = T(weight[k]);
  }
};

template <typename T>
const Window<T>& window() {
  static const Window<T> instance;
  return instance;
}

// The row loops of the active instruction-set variant; double runs the baseline's.
template <typename T>
SsimRows<T> active_rows() {
  if constexpr (std::is_same_v<T, float>) {
#if defined(IESRGS_CPU_AVX2_VARIANT)
    if (cpu_isa::active() == cpu_isa::Isa::kAvx2) return avx2::ssim_rows<float>();
#endif
  }
  return baseline::ssim_rows<T>();
}

// Row-pass results of the image rows that the column pass of one output row needs, indexed by
// image row (rows outside the image included, as zeros).
template <typename T>
class RowRing {
 public:
  RowRing(int planes, int width)
      : planes_(planes), width_(width), values_(size_t(kSsimWindow) * planes * width) {}

  T* row(int image_row, int plane) {
    const int slot = (image_row % kSsimWindow + kSsimWindow) % kSsimWindow;
    return values_.data() + (size_t(slot) * planes_ + plane) * width_;
  }
  // rows[k] = image row (center - kRadius + k) of `plane`
  void column(int center, int plane, const T* rows[kSsimWindow]) {
    for (int k = 0; k < kSsimWindow; ++k) rows[k] = row(center - kRadius + k, plane);
  }
  void clear(int image_row) {
    for (int plane = 0; plane < planes_; ++plane) std::fill_n(row(image_row, plane), width_, T(0));
  }

 private:
  int planes_, width_;
  std::vector<T> values_;
};

// Runs row_pass over image rows [r0 - kRadius, r1 + kRadius) in order and column_pass(r) for each
// output row r in [r0, r1) as soon as its whole column window has been through row_pass.
template <typename RowPass, typename ColumnPass>
void sweep(int r0, int r1, RowPass&& row_pass, ColumnPass&& column_pass) {
  for (int r = r0 - kRadius; r < r1 + kRadius; ++r) {
    row_pass(r);
    if (r - kRadius >= r0) column_pass(r - kRadius);
  }
}

// One band of rows per thread, as wide as the image: each band re-runs the row pass on the
// kRadius rows beyond each of its ends, which costs little next to sharing rows between threads.
std::vector<PixelBox> bands(const ImageShape& shape) {
  const int count = std::min(shape.height, omp_get_max_threads());
  std::vector<PixelBox> boxes;
  for (int band = 0; band < count; ++band)
    boxes.push_back({int(int64_t(shape.height) * band / count),
                     int(int64_t(shape.height) * (band + 1) / count), 0, shape.width});
  return boxes;
}

// body(i, boxes[i]) for every box, in parallel; bands take one thread each, tiles are many and
// uneven, so they go to whichever thread is free. A body allocates its rows' buffers: an exception
// cannot leave an OpenMP region (out of memory would end the program there), so the first one is
// kept and thrown again after it.
template <typename Body>
void for_each_box(const std::vector<PixelBox>& boxes, Body&& body) {
  const int64_t count = int64_t(boxes.size());
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic)
  for (int64_t i = 0; i < count; ++i) {
    try {
      body(i, boxes[i]);
    } catch (...) {
#pragma omp critical(ssim_box_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

// Offset of row r of channel c in a CHW array.
size_t row_offset(const ImageShape& shape, int c, int r) {
  return (size_t(c) * shape.height + r) * shape.width;
}

// Columns of row r that the row pass of `box` reads: [col0 - kRadius, col1 + kRadius) clipped to
// the image, as an offset into the row and into the padded buffer. The padded buffer's other
// values stay zero, the convolution's zero padding.
struct PaddedSpan {
  int first, count, padded_offset;
};

PaddedSpan padded_span(const ImageShape& shape, const PixelBox& box) {
  const int first = std::max(0, box.col0 - kRadius);
  const int last = std::min(shape.width, box.col1 + kRadius);
  return {first, last - first, first - (box.col0 - kRadius)};
}

// What both passes over one box read: the row loops, the two images, and where the box lies.
template <typename T>
struct BoxInputs {
  BoxInputs(const SsimRows<T>& rows, const T* x, const T* y, const ImageShape& shape,
            const PixelBox& box)
      : rows(rows),
        x(x),
        y(y),
        shape(shape),
        box(box),
        width(box.col1 - box.col0),
        span(padded_span(shape, box)) {}

  SsimRows<T> rows;
  const T* x;
  const T* y;
  ImageShape shape;
  PixelBox box;
  int width;
  PaddedSpan span;
};

// The forward pass over the pixels of one box: map and partials there, nothing elsewhere.
template <typename T>
class ForwardBox {
 public:
  ForwardBox(const BoxInputs<T>& in, T* map, T* partials)
      : in_(in),
        map_(map),
        partials_(partials),
        ring_(kMomentPlanes, in.width),
        padded_x_(in.width + 2 * kRadius, T(0)),
        padded_y_(padded_x_),
        stats_(kMomentPlanes * in.width),
        points_((1 + kSsimPartialPlanes) * in.width) {}

  // Sum of the per-channel SSIM over the box.
  double run() {
    if (map_)
      for (int r = in_.box.row0; r < in_.box.row1; ++r)
        std::fill_n(map_ + size_t(r) * in_.shape.width + in_.box.col0, in_.width, T(0));
    double sum = 0;
    for (int c = 0; c < in_.shape.channels; ++c) {
      sweep(
          in_.box.row0, in_.box.row1, [&](int r) { row_pass(r, c); },
          [&](int r) { sum += column_pass(r, c); });
    }
    return sum;
  }

 private:
  MomentRows<T> ring_rows(int r) {
    return {ring_.row(r, 0), ring_.row(r, 1), ring_.row(r, 2), ring_.row(r, 3)};
  }

  void row_pass(int r, int c) {
    if (r < 0 || r >= in_.shape.height) {
      ring_.clear(r);
      return;
    }
    const size_t offset = row_offset(in_.shape, c, r) + in_.span.first;
    std::copy_n(in_.x + offset, in_.span.count, padded_x_.data() + in_.span.padded_offset);
    std::copy_n(in_.y + offset, in_.span.count, padded_y_.data() + in_.span.padded_offset);
    const T* xs[kSsimWindow];
    const T* ys[kSsimWindow];
    for (int k = 0; k < kSsimWindow; ++k) {
      xs[k] = padded_x_.data() + k;
      ys[k] = padded_y_.data() + k;
    }
    in_.rows.moments(window<T>().tap, xs, ys, in_.width, ring_rows(r));
  }

  double column_pass(int r, int c) {
    const int width = in_.width;
    const T* rows[kMomentPlanes][kSsimWindow];
    for (int plane = 0; plane < kMomentPlanes; ++plane) ring_.column(r, plane, rows[plane]);
    T* s = stats_.data();
    const MomentRows<T> stats{s, s + width, s + 2 * width, s + 3 * width};
    in_.rows.sub_window_moments(window<T>().tap, rows[0], rows[1], rows[2], rows[3], width, stats);

    // Value then the kSsimPartialPlanes derivatives, one row each; the derivatives straight into
    // the partials when the backward pass wants them.
    T* values = points_.data();
    T* d[kSsimPartialPlanes];
    for (int plane = 0; plane < kSsimPartialPlanes; ++plane)
      d[plane] = partials_ ? partials_ + plane * in_.shape.values() + row_offset(in_.shape, c, r) +
                                 in_.box.col0
                           : values + size_t(1 + plane) * width;
    in_.rows.points(stats, width, values, d[0], d[1], d[2]);
    if (map_) {
      const T inv_channels = T(1) / in_.shape.channels;
      T* map_row = map_ + size_t(r) * in_.shape.width + in_.box.col0;
      for (int x = 0; x < width; ++x) map_row[x] += values[x] * inv_channels;
    }
    double sum = 0;
    for (int x = 0; x < width; ++x) sum += values[x];
    return sum;
  }

  BoxInputs<T> in_;
  T* map_;
  T* partials_;
  RowRing<T> ring_;
  std::vector<T> padded_x_, padded_y_, stats_, points_;
};

// The gradient of sum_p weight[p] * S_c(p) with respect to x_c(q) is the window-weighted sum over
// the pixels p that see q of the derivatives with respect to mean (times 1), mean square (times
// 2 x(q)) and mean product (times y(q)): three more blurs, as the window is symmetric and the
// zero padding makes the convolution its own adjoint. One box of q at a time.
template <typename T>
class BackwardBox {
 public:
  BackwardBox(const BoxInputs<T>& in, const T* partials, const T* weight, T* grad_x)
      : in_(in),
        partials_(partials),
        weight_(weight),
        grad_x_(grad_x),
        ring_(kSsimPartialPlanes, in.width),
        padded_(size_t(kSsimPartialPlanes) * (in.width + 2 * kRadius), T(0)),
        blurred_(size_t(kSsimPartialPlanes) * in.width) {}

  void run() {
    for (int c = 0; c < in_.shape.channels; ++c)
      sweep(
          in_.box.row0, in_.box.row1, [&](int r) { row_pass(r, c); },
          [&](int r) { column_pass(r, c); });
  }

 private:
  void row_pass(int r, int c) {
    if (r < 0 || r >= in_.shape.height) {
      ring_.clear(r);
      return;
    }
    const T inv_channels = T(1) / in_.shape.channels;
    const T* weight = weight_ + size_t(r) * in_.shape.width + in_.span.first;
    for (int plane = 0; plane < kSsimPartialPlanes; ++plane) {
      T* padded = padded_.data() + size_t(plane) * (in_.width + 2 * kRadius);
      const T* partial =
          partials_ + plane * in_.shape.values() + row_offset(in_.shape, c, r) + in_.span.first;
      T* in_image = padded + in_.span.padded_offset;
      // Partials are only written where some weight is, and may be garbage elsewhere.
      for (int x = 0; x < in_.span.count; ++x)
        in_image[x] = weight[x] != T(0) ? weight[x] * inv_channels * partial[x] : T(0);
      const T* rows[kSsimWindow];
      for (int k = 0; k < kSsimWindow; ++k) rows[k] = padded + k;
      in_.rows.blur(window<T>().tap, rows, in_.width, ring_.row(r, plane));
    }
  }

  void column_pass(int r, int c) {
    const int width = in_.width;
    for (int plane = 0; plane < kSsimPartialPlanes; ++plane) {
      const T* rows[kSsimWindow];
      ring_.column(r, plane, rows);
      in_.rows.blur(window<T>().tap, rows, width, blurred_.data() + size_t(plane) * width);
    }
    const T* d_mean = blurred_.data();
    const T* d_square = d_mean + width;
    const T* d_cross = d_square + width;
    const size_t offset = row_offset(in_.shape, c, r) + in_.box.col0;
    in_.rows.add_gradient(d_mean, d_square, d_cross, in_.x + offset, in_.y + offset, width,
                          grad_x_ + offset);
  }

  BoxInputs<T> in_;
  const T* partials_;
  const T* weight_;
  T* grad_x_;
  RowRing<T> ring_;
  std::vector<T> padded_, blurred_;
};

template <typename T>
bool tile_has_weight(const T* weight, const ImageShape& shape, int tile_row, int tile_col) {
  const int col0 = tile_col * kSsimTile, col1 = std::min(shape.width, col0 + kSsimTile);
  for (int r = tile_row * kSsimTile; r < std::min(shape.height, (tile_row + 1) * kSsimTile); ++r)
    for (int col = col0; col < col1; ++col)
      if (weight[size_t(r) * shape.width + col] != 0) return true;
  return false;
}

}  // namespace

template <typename T>
SsimSupport ssim_support(const T* weight, const ImageShape& shape) {
  check_shape(shape, "ssim_support");
  const int tile_rows = (shape.height + kSsimTile - 1) / kSsimTile;
  const int tile_cols = (shape.width + kSsimTile - 1) / kSsimTile;
  const auto boxes_of = [&](const std::vector<uint8_t>& flags) {
    std::vector<PixelBox> boxes;
    for (int tr = 0; tr < tile_rows; ++tr)
      for (int tc = 0; tc < tile_cols; ++tc)
        if (flags[size_t(tr) * tile_cols + tc])
          boxes.push_back({tr * kSsimTile, std::min(shape.height, (tr + 1) * kSsimTile),
                           tc * kSsimTile, std::min(shape.width, (tc + 1) * kSsimTile)});
    return boxes;
  };
  std::vector<uint8_t> weighted(size_t(tile_rows) * tile_cols, 0);
  // Tile by tile, up to the first nonzero weight: a dense weight is settled by one value per tile.
#pragma omp parallel for
  for (int tr = 0; tr < tile_rows; ++tr)
    for (int tc = 0; tc < tile_cols; ++tc)
      weighted[size_t(tr) * tile_cols + tc] = tile_has_weight(weight, shape, tr, tc);
  SsimSupport support;
  support.tiles = weighted.size();
  support.weighted = boxes_of(weighted);
  if (!support.sparse()) return support;

  // The window of a weighted pixel reaches at most the tiles around its own.
  std::vector<uint8_t> reached(weighted.size(), 0);
  for (const PixelBox& tile : support.weighted)
    for (int r = tile.row0; r < tile.row1; ++r)
      for (int col = tile.col0; col < tile.col1; ++col) {
        if (weight[size_t(r) * shape.width + col] == 0) continue;
        for (int tr = std::max(0, r - kRadius) / kSsimTile;
             tr <= std::min(shape.height - 1, r + kRadius) / kSsimTile; ++tr)
          for (int tc = std::max(0, col - kRadius) / kSsimTile;
               tc <= std::min(shape.width - 1, col + kRadius) / kSsimTile; ++tc)
            reached[size_t(tr) * tile_cols + tc] = 1;
      }
  support.reached = boxes_of(reached);
  return support;
}

template <typename T>
double ssim_in(const T* x, const T* y, const ImageShape& shape, const std::vector<PixelBox>& boxes,
               T* map, T* partials) {
  check_shape(shape, "ssim");
  std::vector<double> box_sums(boxes.size(), 0.0);
  const SsimRows<T> rows = active_rows<T>();
  for_each_box(boxes, [&](int64_t i, const PixelBox& box) {
    box_sums[i] = ForwardBox<T>({rows, x, y, shape, box}, map, partials).run();
  });
  double sum = 0;
  for (double s : box_sums) sum += s;
  return sum;
}

template <typename T>
void ssim_backward_in(const T* x, const T* y, const ImageShape& shape,
                      const std::vector<PixelBox>& boxes, const T* partials, const T* weight,
                      T* grad_x) {
  check_shape(shape, "ssim_backward");
  const SsimRows<T> rows = active_rows<T>();
  for_each_box(boxes, [&](int64_t, const PixelBox& box) {
    BackwardBox<T>({rows, x, y, shape, box}, partials, weight, grad_x).run();
  });
}

template <typename T>
double ssim(const T* x, const T* y, const ImageShape& shape, T* map, T* partials) {
  return ssim_in(x, y, shape, bands(shape), map, partials) / double(shape.values());
}

template <typename T>
void ssim_backward(const T* x, const T* y, const ImageShape& shape, const T* partials,
                   const T* weight, T* grad_x) {
  ssim_backward_in(x, y, shape, bands(shape), partials, weight, grad_x);
}

#define IESRGS_INSTANTIATE_SSIM(T)                                                                 \
  template SsimSupport ssim_support(const T*, const ImageShape&);                                  \
  template double ssim_in(const T*, const T*, const ImageShape&, const std::vector<PixelBox>&, T*, \
                          T*);                                                                     \
  template void ssim_backward_in(const T*, const T*, const ImageShape&,                            \
                                 const std::vector<PixelBox>&, const T*, const T*, T*);            \
  template double ssim(const T*, const T*, const ImageShape&, T*, T*);                             \
  template void ssim_backward(const T*, const T*, const ImageShape&, const T*, const T*, T*);
IESRGS_INSTANTIATE_SSIM(float)
IESRGS_INSTANTIATE_SSIM(double)
#undef IESRGS_INSTANTIATE_SSIM

}  // namespace iesrgs::loss
