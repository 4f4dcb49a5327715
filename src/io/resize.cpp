#include "io/resize.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/error.hpp"

namespace iesrgs {

namespace {

// PIL keeps 8 bits for the result and 2 for the overshoot of the negative lobes.
constexpr int kPrecisionBits = 32 - 8 - 2;
constexpr double kBicubicSupport = 2.0;
// Below this many multiply-adds (or samples) waking a thread team costs more than it saves.
constexpr size_t kMinParallelWork = size_t(1) << 16;

double bicubic(double x) {
  constexpr double a = -0.5;
  x = std::abs(x);
  if (x < 1.0) return ((a + 2.0) * x - (a + 3.0)) * x * x + 1;
  if (x < 2.0) return (((x - 5) * x + 8) * x - 4) * a;
  return 0.0;
}

// Normalised filter taps of one axis: output i reads length[i] inputs from first[i] on, with the
// weights at weights[i * stride]. Computed in double exactly as PIL does, so that rounding to
// fixed point afterwards gives PIL's integers bit for bit.
struct Windows {
  int stride = 0;
  std::vector<int> first, length;
  std::vector<double> weights;
};

Windows bicubic_windows(int in_size, int out_size) {
  // PIL passes the box edges as floats; in_size is exact in a float for any real image.
  const double scale = double(float(in_size)) / out_size;
  const double filter_scale = std::max(scale, 1.0);  // widen the kernel only when reducing
  const double support = kBicubicSupport * filter_scale;
  const double inv_filter_scale = 1.0 / filter_scale;

  Windows windows;
  windows.stride = std::min(int(std::ceil(support)) * 2 + 1, in_size);
  windows.first.resize(out_size);
  windows.length.resize(out_size);
  windows.weights.assign(size_t(out_size) * windows.stride, 0.0);
  for (int i = 0; i < out_size; ++i) {
    const double center = (i + 0.5) * scale;
    const int lo = std::max(int(center - support + 0.5), 0);
    const int hi = std::min(int(center + support + 0.5), in_size);
    double* w = &windows.weights[size_t(i) * windows.stride];
    double sum = 0.0;
    for (int x = 0; x < hi - lo; ++x) {
      w[x] = bicubic((x + lo - center + 0.5) * inv_filter_scale);
      sum += w[x];
    }
    if (sum != 0.0)
      for (int x = 0; x < hi - lo; ++x) w[x] /= sum;
    windows.first[i] = lo;
    windows.length[i] = hi - lo;
  }
  return windows;
}

// PIL's 8-bit arithmetic: weights in fixed point, accumulation starting at one half (rounding),
// result shifted back and clipped.
struct FixedPoint {
  using Image = Image8;
  using Sample = uint8_t;
  using Weight = int32_t;
  using Sum = int32_t;
  static constexpr Sum kStart = 1 << (kPrecisionBits - 1);

  static Weight weight(double w) {
    return int32_t(w < 0 ? -0.5 + w * (1 << kPrecisionBits) : 0.5 + w * (1 << kPrecisionBits));
  }
  static Sample finish(Sum sum) { return uint8_t(std::clamp(sum >> kPrecisionBits, 0, 255)); }
};

// Plain float: same weights, no quantization and no clipping.
struct FloatingPoint {
  using Image = iesrgs::Image;
  using Sample = float;
  using Weight = float;
  using Sum = float;
  static constexpr Sum kStart = 0.f;

  static Weight weight(double w) { return float(w); }
  static Sample finish(Sum sum) { return sum; }
};

template <class Arith>
struct Kernel {
  using Weight = typename Arith::Weight;

  explicit Kernel(const Windows& w)
      : stride(w.stride), first(w.first), length(w.length), weights(w.weights.size()) {
    std::transform(w.weights.begin(), w.weights.end(), weights.begin(), Arith::weight);
  }
  const Weight* taps(int i) const { return &weights[size_t(i) * stride]; }

  int stride;
  std::vector<int> first, length;
  std::vector<Weight> weights;
};

// Resamples rows [row0, row0 + out.height) of `in` along x; channels fixed at compile time so the
// per-pixel accumulators stay in registers.
template <class Arith, int C>
void horizontal_pass_fixed_channels(const typename Arith::Image& in, int row0,
                                    const Kernel<Arith>& kernel, typename Arith::Image& out) {
  using Sample = typename Arith::Sample;
#pragma omp parallel for schedule(static) if (out.data.size() * kernel.stride > kMinParallelWork)
  for (int y = 0; y < out.height; ++y) {
    const Sample* src = &in.data[size_t(row0 + y) * in.width * C];
    Sample* dst = &out.data[size_t(y) * out.width * C];
    for (int x = 0; x < out.width; ++x) {
      const auto* w = kernel.taps(x);
      const Sample* s = src + size_t(kernel.first[x]) * C;
      typename Arith::Sum sum[C];
      std::fill(sum, sum + C, Arith::kStart);
      for (int k = 0; k < kernel.length[x]; ++k, s += C)
        for (int c = 0; c < C; ++c) sum[c] += s[c] * w[k];
      for (int c = 0; c < C; ++c) dst[size_t(x) * C + c] = Arith::finish(sum[c]);
    }
  }
}

template <class Arith>
void horizontal_pass(const typename Arith::Image& in, int row0, const Kernel<Arith>& kernel,
                     typename Arith::Image& out) {
  switch (in.channels) {
    case 1:
      return horizontal_pass_fixed_channels<Arith, 1>(in, row0, kernel, out);
    case 2:
      return horizontal_pass_fixed_channels<Arith, 2>(in, row0, kernel, out);
    case 3:
      return horizontal_pass_fixed_channels<Arith, 3>(in, row0, kernel, out);
    default:
      return horizontal_pass_fixed_channels<Arith, 4>(in, row0, kernel, out);
  }
}

// Resamples along y. Every sample of a row is independent here, so whole rows are accumulated
// into a row of sums: contiguous, vectorisable, and blind to the channel count.
template <class Arith>
void vertical_pass(const typename Arith::Image& in, const Kernel<Arith>& kernel,
                   typename Arith::Image& out) {
  using Sample = typename Arith::Sample;
  const size_t row_size = size_t(in.width) * in.channels;
  // One row of sums per thread, allocated here: out of memory inside the region would end the
  // program.
  std::vector<typename Arith::Sum> all_sums(row_size * omp_get_max_threads());
#pragma omp parallel if (out.data.size() * kernel.stride > kMinParallelWork)
  {
    typename Arith::Sum* sums = all_sums.data() + row_size * omp_get_thread_num();
#pragma omp for schedule(static)
    for (int y = 0; y < out.height; ++y) {
      const auto* w = kernel.taps(y);
      std::fill(sums, sums + row_size, Arith::kStart);
      for (int k = 0; k < kernel.length[y]; ++k) {
        const Sample* src = &in.data[size_t(kernel.first[y] + k) * row_size];
        for (size_t i = 0; i < row_size; ++i) sums[i] += src[i] * w[k];
      }
      Sample* dst = &out.data[size_t(y) * row_size];
      for (size_t i = 0; i < row_size; ++i) dst[i] = Arith::finish(sums[i]);
    }
  }
}

// PIL's two passes: horizontal first, over only the rows the vertical pass will read, and each
// pass skipped when its axis keeps its size.
template <class Arith>
typename Arith::Image resample(const typename Arith::Image& in, int width, int height) {
  using Image = typename Arith::Image;
  Windows rows = bicubic_windows(in.height, height);
  Image current;
  const Image* source = &in;
  if (width != in.width) {
    const int row0 = rows.first.front();
    const int row_end = rows.first.back() + rows.length.back();
    for (int& first : rows.first) first -= row0;
    current = Image(width, row_end - row0, in.channels);
    horizontal_pass(in, row0, Kernel<Arith>(bicubic_windows(in.width, width)), current);
    source = &current;
  }
  if (height != in.height) {
    Image out(source->width, height, in.channels);
    vertical_pass(*source, Kernel<Arith>(rows), out);
    return out;
  }
  return current;
}

// PIL's RGBA -> RGBa (and LA -> La): color times alpha / 255, rounded with its shift trick.
void premultiply(Image8& image) {
  const int c = image.channels;
#pragma omp parallel for schedule(static) if (image.data.size() > kMinParallelWork)
  for (size_t p = 0; p < image.data.size(); p += c) {
    const unsigned alpha = image.data[p + c - 1];
    for (int k = 0; k < c - 1; ++k) {
      const unsigned t = image.data[p + k] * alpha + 128;
      image.data[p + k] = uint8_t(((t >> 8) + t) >> 8);
    }
  }
}

// ceil(2^32 / d): turns the divisions by alpha below into multiplications, exact because the
// numerators (255 * color) stay below 2^16, far too small for the rounding up to ever show.
constexpr std::array<uint64_t, 256> reciprocals() {
  std::array<uint64_t, 256> r{};
  for (uint64_t d = 1; d < 256; ++d) r[d] = ((uint64_t(1) << 32) + d - 1) / d;
  return r;
}

// PIL's RGBa -> RGBA: truncating division, colors of opaque and fully transparent pixels kept.
void unpremultiply(Image8& image) {
  static constexpr std::array<uint64_t, 256> kReciprocal = reciprocals();
  const int c = image.channels;
#pragma omp parallel for schedule(static) if (image.data.size() > kMinParallelWork)
  for (size_t p = 0; p < image.data.size(); p += c) {
    const unsigned alpha = image.data[p + c - 1];
    if (alpha == 0 || alpha == 255) continue;
    for (int k = 0; k < c - 1; ++k) {
      const uint64_t quotient = (255u * image.data[p + k] * kReciprocal[alpha]) >> 32;
      image.data[p + k] = uint8_t(std::min<uint64_t>(quotient, 255));
    }
  }
}

template <class AnyImage>
void check_resizable(const AnyImage& image, int width, int height) {
  if (width <= 0 || height <= 0) fail("resize: invalid target size {}x{}", width, height);
  if (image.width <= 0 || image.height <= 0 || image.channels < 1 || image.channels > 4 ||
      image.data.size() != size_t(image.width) * image.height * image.channels)
    fail("resize: invalid source image {}x{} with {} channels and {} samples", image.width,
         image.height, image.channels, image.data.size());
}

}  // namespace

Image8 resize_bicubic(const Image8& image, int width, int height) {
  check_resizable(image, width, height);
  if (width == image.width && height == image.height) return image;
  const bool has_alpha = image.channels == 2 || image.channels == 4;
  if (!has_alpha) return resample<FixedPoint>(image, width, height);
  Image8 premultiplied = image;
  premultiply(premultiplied);
  Image8 out = resample<FixedPoint>(premultiplied, width, height);
  unpremultiply(out);
  return out;
}

Image resize_bicubic(const Image& image, int width, int height) {
  check_resizable(image, width, height);
  if (width == image.width && height == image.height) return image;
  return resample<FloatingPoint>(image, width, height);
}

}  // namespace iesrgs
