#pragma once
// The pixel-row loops of the CPU SSIM (ssim.cpp), where its time goes: compiled once per
// instruction-set variant (core/cpu_isa_variant.hpp), without fused multiply-adds, so that every
// variant gives the same bits and the wider ones only run more pixels at once.
#include "loss/ssim.hpp"

namespace iesrgs::loss {

// Window statistics of one channel along one row: means of x and y, spread (sum of the two
// variances) and covariance.
template <typename T>
struct MomentRows {
  T* mean_x;
  T* mean_y;
  T* spread;
  T* cross;
};

template <typename T>
struct SsimRows {
  // out[x] = the weighted statistics of the window taps xs[k][x], ys[k][x] (k < kSsimWindow).
  void (*moments)(const T* tap, const T* const* xs, const T* const* ys, int width,
                  MomentRows<T> out);
  // The same over samples that are themselves window means, with their own spreads and
  // covariances: the column pass over the row pass's statistics.
  void (*sub_window_moments)(const T* tap, const T* const* xs, const T* const* ys,
                             const T* const* spreads, const T* const* crosses, int width,
                             MomentRows<T> out);
  // SSIM and its derivatives (ssim_point.hpp) at every pixel of a row of statistics.
  void (*points)(MomentRows<T> stats, int width, T* value, T* d_mean, T* d_square, T* d_cross);
  // out[x] = sum_k tap[k] * rows[k][x].
  void (*blur)(const T* tap, const T* const* rows, int width, T* out);
  // grad_x[x] += d_mean[x] + 2 x[x] d_square[x] + y[x] d_cross[x].
  void (*add_gradient)(const T* d_mean, const T* d_square, const T* d_cross, const T* x, const T* y,
                       int width, T* grad_x);
};

// Defined by the compilations of ssim_rows.cpp: the baseline for float and double, the AVX2 one
// for float where IESRGS_CPU_AVX2_VARIANT is defined.
namespace baseline {
template <typename T>
SsimRows<T> ssim_rows();
}  // namespace baseline
namespace avx2 {
template <typename T>
SsimRows<T> ssim_rows();
}  // namespace avx2

}  // namespace iesrgs::loss
