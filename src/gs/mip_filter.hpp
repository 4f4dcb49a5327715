#pragma once
// Mip-Splatting's two low-pass filters, as opacity-preserving convolutions of the Gaussian.
// 3D smoothing filter: the world-space covariance gets filter_std^2 on its diagonal (in the
// Gaussian's own frame, i.e. on every scale) and the opacity is scaled so that the integral is
// unchanged. 2D mip filter: the screen-space covariance gets kMipFilterVariance on its diagonal
// and the opacity the matching factor. Models trained without it (3DGS, most .spz files) are
// drawn with 3DGS's dilation instead, as they were trained: more variance, opacity unchanged.
#include <cmath>

#include "core/geometry.hpp"

namespace iesrgs::gs {

// Gaussians at camera z at or below this are culled, as 3DGS does; the 3D filter counts the
// cameras that see a Gaussian beyond it.
constexpr double kNearPlane = 0.2;
// Variance in pixels^2, at the sampling rate of the closest camera that sees a Gaussian, of the
// 3D smoothing filter.
constexpr double kFilter3dVariance = 0.2;

// The 3D filter's std for a Gaussian at camera depth `depth` of a camera of focal length `focal`.
inline double filter3d_std_at(double depth, double focal) {
  return depth / focal * std::sqrt(kFilter3dVariance);
}

// Variance in pixels^2 of the screen-space box-filter approximation.
constexpr double kMipFilterVariance = 0.1;
// 3DGS's screen-space dilation, in pixels^2, for models without the mip filter ("classic").
constexpr double kClassicDilation = 0.3;
// Floor on det(cov) / det(cov + filter), for numerical stability, as 3DGS's antialiasing mode
// (Mip-Splatting's code floors each determinant instead): a needle splat keeps 0.5 % opacity.
constexpr double kMinMipDetRatio = 0.000025;

// scale: activated scales; var: effective variances s^2 + f^2; returns the opacity factor
// sqrt(prod(s^2) / prod(s^2 + f^2)).
template <typename T>
IESRGS_HD T filter3d(const T* scale, T filter_std, T* var) {
  const T f2 = filter_std * filter_std;
  T ratio = 1;
  for (int k = 0; k < 3; ++k) {
    const T s2 = scale[k] * scale[k];
    var[k] = s2 + f2;
    ratio *= s2 / var[k];
  }
  return hd::sqrt(ratio);
}

// dlog_scale = dL/d(log s) from dL/dvar and dL/dfactor. Taken with respect to the log scale,
// which the model stores, it needs no division by s: a scale whose exp underflowed to 0 gets a
// finite gradient.
template <typename T>
IESRGS_HD void filter3d_backward(const T* scale, T filter_std, const T* dvar, T dfactor,
                                 T* dlog_scale) {
  T var[3];
  const T factor = filter3d(scale, filter_std, var);
  const T f2 = filter_std * filter_std;
  // d log(factor) / d log(s_k) = f^2 / (s_k^2 + f^2)
  for (int k = 0; k < 3; ++k)
    dlog_scale[k] = T(2) * scale[k] * scale[k] * dvar[k] + dfactor * factor * f2 / var[k];
}

// The variance the screen-space filter adds: the mip filter's, or 3DGS's dilation.
IESRGS_HD double filter2d_variance(bool antialiased) {
  return antialiased ? kMipFilterVariance : kClassicDilation;
}

// Returns the opacity factor (1 for the dilation) and writes the filtered covariance.
template <typename T>
IESRGS_HD T filter2d(const Sym2<T>& cov, bool antialiased, Sym2<T>& filtered) {
  const T h = T(filter2d_variance(antialiased));
  filtered = {cov.xx + h, cov.xy, cov.yy + h};
  if (!antialiased) return T(1);
  return hd::sqrt(hd::max(T(kMinMipDetRatio), det(cov) / det(filtered)));
}

// dL/dcov from dL/dfiltered and dL/dfactor (no factor gradient where the floor is active).
template <typename T>
IESRGS_HD Sym2<T> filter2d_backward(const Sym2<T>& cov, bool antialiased, const Sym2<T>& dfiltered,
                                    T dfactor) {
  Sym2<T> dcov = dfiltered;
  if (!antialiased) return dcov;
  Sym2<T> filtered;
  const T factor = filter2d(cov, antialiased, filtered);
  const T det0 = det(cov), det1 = det(filtered);
  const T r = det0 / det1;
  // factor = sqrt(det0 / det1); d det / d(xx, xy, yy) = (yy, -2 xy, xx)
  const T g = hd::select(r <= T(kMinMipDetRatio), T(0), dfactor / (T(2) * factor * det1));
  dcov.xx += g * (cov.yy - r * filtered.yy);
  dcov.xy += g * T(-2) * (cov.xy - r * filtered.xy);
  dcov.yy += g * (cov.xx - r * filtered.xx);
  return dcov;
}

}  // namespace iesrgs::gs
