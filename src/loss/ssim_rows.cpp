// The SSIM row loops of ssim_rows.hpp, in the namespace of this compilation's instruction-set
// variant. Plain loops over raw arrays: the compiler vectorizes them along the row.
#include "loss/ssim_rows.hpp"
#include "core/cpu_isa_variant.hpp"
#include "loss/ssim_point.hpp"

namespace iesrgs::loss::IESRGS_CPU_ISA_NAMESPACE {
namespace {

// By the law of total variance the spread of a window of sub-windows is that of the sub-windows
// plus that of their means. Computing it from deviations rather than as E[x^2] - E[x]^2 keeps
// float SSIM within ~1e-6 of float64 in flat regions, where that cancellation, divided by
// C2 = 9e-4, costs ~1e-4. The taps run innermost, fully unrolled, so that the sums stay in
// registers while the loop over x is vectorized.
template <bool kSubWindows, typename T>
void combine_moments(const T* tap, const T* const* xs, const T* const* ys, const T* const* spreads,
                     const T* const* crosses, int width, T* __restrict mean_x_out,
                     T* __restrict mean_y_out, T* __restrict spread_out, T* __restrict cross_out) {
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
    mean_x_out[x] = mean_x;
    mean_y_out[x] = mean_y;
    spread_out[x] = spread;
    cross_out[x] = cross;
  }
}

template <typename T>
void moments(const T* tap, const T* const* xs, const T* const* ys, int width, MomentRows<T> out) {
  combine_moments<false, T>(tap, xs, ys, nullptr, nullptr, width, out.mean_x, out.mean_y,
                            out.spread, out.cross);
}

template <typename T>
void sub_window_moments(const T* tap, const T* const* xs, const T* const* ys,
                        const T* const* spreads, const T* const* crosses, int width,
                        MomentRows<T> out) {
  combine_moments<true, T>(tap, xs, ys, spreads, crosses, width, out.mean_x, out.mean_y, out.spread,
                           out.cross);
}

template <typename T>
void points(MomentRows<T> stats, int width, T* __restrict value, T* __restrict d_mean,
            T* __restrict d_square, T* __restrict d_cross) {
  for (int x = 0; x < width; ++x) {
    const SsimPoint<T> p =
        ssim_point(stats.mean_x[x], stats.mean_y[x], stats.spread[x], stats.cross[x]);
    value[x] = p.value;
    d_mean[x] = p.d_mean;
    d_square[x] = p.d_square;
    d_cross[x] = p.d_cross;
  }
}

template <typename T>
void blur(const T* tap, const T* const* rows, int width, T* __restrict out) {
  for (int x = 0; x < width; ++x) {
    T sum = 0;
#pragma GCC unroll 16
    for (int k = 0; k < kSsimWindow; ++k) sum += tap[k] * rows[k][x];
    out[x] = sum;
  }
}

template <typename T>
void add_gradient(const T* d_mean, const T* d_square, const T* d_cross, const T* x, const T* y,
                  int width, T* __restrict grad_x) {
  for (int i = 0; i < width; ++i)
    grad_x[i] += d_mean[i] + 2 * x[i] * d_square[i] + y[i] * d_cross[i];
}

}  // namespace

template <typename T>
SsimRows<T> ssim_rows() {
  return {&moments<T>, &sub_window_moments<T>, &points<T>, &blur<T>, &add_gradient<T>};
}

template SsimRows<float> ssim_rows();
#if !defined(IESRGS_CPU_ISA_AVX2)
template SsimRows<double> ssim_rows();  // the gradient checks run in double, on the baseline
#endif

}  // namespace iesrgs::loss::IESRGS_CPU_ISA_NAMESPACE
