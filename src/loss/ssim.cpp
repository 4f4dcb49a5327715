#include "loss/ssim.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace iesrgs::loss {
namespace {

constexpr int kRadius = kSsimWindow / 2;
constexpr int kMomentPlanes = 4;   // MomentRows
constexpr int kPartialPlanes = 3;  // d/d mean, d/d mean square, d/d mean product

// The normalized 1-D Gaussian; the 2-D window is its outer product.
template <typename T>
struct Window {
  T tap[kSsimWindow];

  Window() {
    double weight[kSsimWindow], sum = 0;
    for (int k = 0; k < kSsimWindow; ++k) {
      const double d = k - kRadius;
      weight[k] = std::exp(-d * d / (2 * kSsimSigma * kSsimSigma));
      sum += weight[k];
    }
    for (int k = 0; k < kSsimWindow; ++k) tap[k] = T(weight[k] / sum);
  }
};

template <typename T>
const Window<T>& window() {
  static const Window<T> instance;
  return instance;
}

// out[x] = sum_k tap[k] * rows[k][x]. The taps run innermost, fully unrolled, so that the sums
// stay in registers while the loop over x is vectorized.
template <typename T>
void blur(const T* tap, const T* const* rows, int width, T* __restrict out) {
  for (int x = 0; x < width; ++x) {
    T sum = 0;
#pragma GCC unroll 16
    for (int k = 0; k < kSsimWindow; ++k) sum += tap[k] * rows[k][x];
    out[x] = sum;
  }
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

// One band of rows per thread: each band re-runs the row pass on the kRadius rows beyond each of
// its ends, which costs little next to sharing rows between threads.
int band_count(int height) {
  return std::min(height, omp_get_max_threads());
}

// body(band, r0, r1) for the bands [r0, r1) of the rows, in parallel.
template <typename Body>
void for_each_band(int height, Body&& body) {
  const int bands = band_count(height);
#pragma omp parallel for schedule(static, 1)
  for (int band = 0; band < bands; ++band)
    body(band, int(int64_t(height) * band / bands), int(int64_t(height) * (band + 1) / bands));
}

// Offset of row r of channel c in a CHW array.
size_t row_offset(const ImageShape& shape, int c, int r) {
  return (size_t(c) * shape.height + r) * shape.width;
}

// Copies row r of channel c into padded[kRadius, kRadius + width); the kRadius values at either
// end stay zero, the convolution's zero padding.
template <typename T>
void copy_padded(const T* image, const ImageShape& shape, int c, int r, T* padded) {
  std::copy_n(image + row_offset(shape, c, r), shape.width, padded + kRadius);
}

// Window statistics of one channel along one row: means of x and y, spread (sum of the two
// variances) and covariance.
template <typename T>
struct MomentRows {
  T* mean_x;
  T* mean_y;
  T* spread;
  T* cross;
};

// Weighted statistics of the samples xs[k][x], ys[k][x] (k over the window taps), each the mean of
// a sub-window with its own spread and covariance spreads[k][x], crosses[k][x] (unused when the
// samples are single pixels). By the law of total variance the spread of the whole window is that
// of the sub-windows plus that of their means. Computing it from deviations rather than as
// E[x^2] - E[x]^2 keeps float SSIM within ~1e-6 of float64 in flat regions, where that
// cancellation, divided by C2 = 9e-4, costs ~1e-4.
template <bool kSubWindows, typename T>
void combine_moments(const T* tap, const T* const* xs, const T* const* ys, const T* const* spreads,
                     const T* const* crosses, int width, MomentRows<T> out) {
  for (int x = 0; x < width; ++x) {
    T mean_x = 0, mean_y = 0, spread = 0, cross = 0;
#pragma GCC unroll 16
    for (int k = 0; k < kSsimWindow; ++k) {
      mean_x += tap[k] * xs[k][x];
      mean_y += tap[k] * ys[k][x];
    }
#pragma GCC unroll 16
    for (int k = 0; k < kSsimWindow; ++k) {
      const T dx = xs[k][x] - mean_x, dy = ys[k][x] - mean_y;
      spread += tap[k] * (dx * dx + dy * dy);
      cross += tap[k] * dx * dy;
    }
    if constexpr (kSubWindows) {
#pragma GCC unroll 16
      for (int k = 0; k < kSsimWindow; ++k) {
        spread += tap[k] * spreads[k][x];
        cross += tap[k] * crosses[k][x];
      }
    }
    out.mean_x[x] = mean_x;
    out.mean_y[x] = mean_y;
    out.spread[x] = spread;
    out.cross[x] = cross;
  }
}

// SSIM of one channel at one pixel and its derivatives with respect to the window mean, mean
// square and mean product of x (the convolutions of x, x^2 and x*y).
template <typename T>
struct SsimPoint {
  T value, d_mean, d_square, d_cross;
};

template <typename T>
SsimPoint<T> ssim_point(T mean_x, T mean_y, T spread, T cross) {
  const T c1 = T(kSsimC1), c2 = T(kSsimC2);
  const T a1 = 2 * mean_x * mean_y + c1, a2 = 2 * cross + c2;
  const T b1 = mean_x * mean_x + mean_y * mean_y + c1, b2 = spread + c2;
  const T inv_b = 1 / (b1 * b2);
  const T value = a1 * a2 * inv_b;
  // The variances are the mean square minus the squared mean, hence the b2 - b1 and a2 - a1
  // terms of the mean's derivative.
  return {value, 2 * (mean_y * (a2 - a1) - value * mean_x * (b2 - b1)) * inv_b, -value / b2,
          2 * a1 * inv_b};
}

template <typename T>
class ForwardBand {
 public:
  ForwardBand(const T* x, const T* y, const ImageShape& shape, T* map, T* partials)
      : x_(x),
        y_(y),
        shape_(shape),
        map_(map),
        partials_(partials),
        ring_(kMomentPlanes, shape.width),
        padded_x_(shape.width + 2 * kRadius, T(0)),
        padded_y_(padded_x_),
        stats_(kMomentPlanes * shape.width),
        points_((1 + kPartialPlanes) * shape.width) {}

  // Sum of the per-channel SSIM over rows [r0, r1).
  double run(int r0, int r1) {
    const int width = shape_.width;
    if (map_) std::fill(map_ + size_t(r0) * width, map_ + size_t(r1) * width, T(0));
    double sum = 0;
    for (int c = 0; c < shape_.channels; ++c) {
      sweep(
          r0, r1, [&](int r) { row_pass(r, c); }, [&](int r) { sum += column_pass(r, c); });
    }
    return sum;
  }

 private:
  MomentRows<T> ring_rows(int r) {
    return {ring_.row(r, 0), ring_.row(r, 1), ring_.row(r, 2), ring_.row(r, 3)};
  }

  void row_pass(int r, int c) {
    if (r < 0 || r >= shape_.height) {
      ring_.clear(r);
      return;
    }
    copy_padded(x_, shape_, c, r, padded_x_.data());
    copy_padded(y_, shape_, c, r, padded_y_.data());
    const T* xs[kSsimWindow];
    const T* ys[kSsimWindow];
    for (int k = 0; k < kSsimWindow; ++k) {
      xs[k] = padded_x_.data() + k;
      ys[k] = padded_y_.data() + k;
    }
    combine_moments<false, T>(window<T>().tap, xs, ys, nullptr, nullptr, shape_.width,
                              ring_rows(r));
  }

  double column_pass(int r, int c) {
    const int width = shape_.width;
    const T* rows[kMomentPlanes][kSsimWindow];
    for (int plane = 0; plane < kMomentPlanes; ++plane) ring_.column(r, plane, rows[plane]);
    T* s = stats_.data();
    const MomentRows<T> stats{s, s + width, s + 2 * width, s + 3 * width};
    combine_moments<true, T>(window<T>().tap, rows[0], rows[1], rows[2], rows[3], width, stats);

    // Value then the kPartialPlanes derivatives, one row each.
    T* values = points_.data();
    T* d_mean = values + width;
    T* d_square = d_mean + width;
    T* d_cross = d_square + width;
    for (int x = 0; x < width; ++x) {
      const SsimPoint<T> p =
          ssim_point(stats.mean_x[x], stats.mean_y[x], stats.spread[x], stats.cross[x]);
      values[x] = p.value;
      d_mean[x] = p.d_mean;
      d_square[x] = p.d_square;
      d_cross[x] = p.d_cross;
    }
    if (partials_) {
      const size_t offset = row_offset(shape_, c, r);
      for (int plane = 0; plane < kPartialPlanes; ++plane)
        std::copy_n(d_mean + size_t(plane) * width, width,
                    partials_ + plane * shape_.values() + offset);
    }
    if (map_) {
      const T inv_channels = T(1) / shape_.channels;
      T* map_row = map_ + size_t(r) * width;
      for (int x = 0; x < width; ++x) map_row[x] += values[x] * inv_channels;
    }
    double sum = 0;
    for (int x = 0; x < width; ++x) sum += values[x];
    return sum;
  }

  const T* x_;
  const T* y_;
  ImageShape shape_;
  T* map_;
  T* partials_;
  RowRing<T> ring_;
  std::vector<T> padded_x_, padded_y_, stats_, points_;
};

// The gradient of sum_p weight[p] * S_c(p) with respect to x_c(q) is the window-weighted sum over
// the pixels p that see q of the derivatives with respect to mean (times 1), mean square (times
// 2 x(q)) and mean product (times y(q)): three more blurs, as the window is symmetric and the
// zero padding makes the convolution its own adjoint.
template <typename T>
class BackwardBand {
 public:
  BackwardBand(const T* x, const T* y, const ImageShape& shape, const T* partials, const T* weight,
               T* grad_x)
      : x_(x),
        y_(y),
        shape_(shape),
        partials_(partials),
        weight_(weight),
        grad_x_(grad_x),
        ring_(kPartialPlanes, shape.width),
        padded_(size_t(kPartialPlanes) * (shape.width + 2 * kRadius), T(0)),
        blurred_(size_t(kPartialPlanes) * shape.width) {}

  void run(int r0, int r1) {
    for (int c = 0; c < shape_.channels; ++c)
      sweep(
          r0, r1, [&](int r) { row_pass(r, c); }, [&](int r) { column_pass(r, c); });
  }

 private:
  void row_pass(int r, int c) {
    if (r < 0 || r >= shape_.height) {
      ring_.clear(r);
      return;
    }
    const int width = shape_.width;
    const T inv_channels = T(1) / shape_.channels;
    const T* weight = weight_ + size_t(r) * width;
    for (int plane = 0; plane < kPartialPlanes; ++plane) {
      T* padded = padded_.data() + size_t(plane) * (width + 2 * kRadius);
      const T* partial = partials_ + plane * shape_.values() + row_offset(shape_, c, r);
      for (int x = 0; x < width; ++x) padded[kRadius + x] = weight[x] * inv_channels * partial[x];
      const T* rows[kSsimWindow];
      for (int k = 0; k < kSsimWindow; ++k) rows[k] = padded + k;
      blur(window<T>().tap, rows, width, ring_.row(r, plane));
    }
  }

  void column_pass(int r, int c) {
    const int width = shape_.width;
    for (int plane = 0; plane < kPartialPlanes; ++plane) {
      const T* rows[kSsimWindow];
      ring_.column(r, plane, rows);
      blur(window<T>().tap, rows, width, blurred_.data() + size_t(plane) * width);
    }
    const T* d_mean = blurred_.data();
    const T* d_square = d_mean + width;
    const T* d_cross = d_square + width;
    const size_t offset = row_offset(shape_, c, r);
    const T* x = x_ + offset;
    const T* y = y_ + offset;
    T* grad_x = grad_x_ + offset;
    for (int i = 0; i < width; ++i)
      grad_x[i] += d_mean[i] + 2 * x[i] * d_square[i] + y[i] * d_cross[i];
  }

  const T* x_;
  const T* y_;
  ImageShape shape_;
  const T* partials_;
  const T* weight_;
  T* grad_x_;
  RowRing<T> ring_;
  std::vector<T> padded_, blurred_;
};

}  // namespace

template <typename T>
double ssim(const T* x, const T* y, const ImageShape& shape, T* map, T* partials) {
  check_shape(shape, "ssim");
  std::vector<double> band_sums(band_count(shape.height), 0.0);
  for_each_band(shape.height, [&](int band, int r0, int r1) {
    band_sums[band] = ForwardBand<T>(x, y, shape, map, partials).run(r0, r1);
  });
  double sum = 0;
  for (double s : band_sums) sum += s;
  return sum / double(shape.values());
}

template <typename T>
void ssim_backward(const T* x, const T* y, const ImageShape& shape, const T* partials,
                   const T* weight, T* grad_x) {
  check_shape(shape, "ssim_backward");
  for_each_band(shape.height, [&](int, int r0, int r1) {
    BackwardBand<T>(x, y, shape, partials, weight, grad_x).run(r0, r1);
  });
}

template double ssim(const float*, const float*, const ImageShape&, float*, float*);
template double ssim(const double*, const double*, const ImageShape&, double*, double*);
template void ssim_backward(const float*, const float*, const ImageShape&, const float*,
                            const float*, float*);
template void ssim_backward(const double*, const double*, const ImageShape&, const double*,
                            const double*, double*);

}  // namespace iesrgs::loss
