#pragma once
// Per-pixel evaluation of a splat, shared by the forward and backward blending kernels. The
// functions are templated on the value type V as well, so that the CPU kernels can evaluate four
// pixels at once with SIMD packs.
#include "core/hd.hpp"
#include "raster/types.hpp"

namespace iesrgs::raster {

// Blending thresholds as float constants, so that the double instantiation cuts exactly where
// the float one does: e.g. two splats at the 0.99 cap leave a transmittance just below 1e-4 in
// float (the pixel stops) but just above it with a double 0.99.
constexpr float kMinAlpha = 1.0f / 255.0f;
constexpr float kMaxAlpha = 0.99f;
constexpr float kMinTransmittance = 1e-4f;

// Exponent of the splat's Gaussian; (dx, dy) is the mean minus the pixel center.
template <typename T, typename V>
IESRGS_HD V splat_power(const Splat<T>& s, V dx, V dy) {
  return T(-0.5) * (s.conic_xx * dx * dx + s.conic_yy * dy * dy) - s.conic_xy * dx * dy;
}

// exp(x) for the Gaussian falloff, x <= 0; positive x (only a rounding error can produce it, and
// the splat is skipped there) is treated as 0 so that no lane overflows.
template <typename T>
IESRGS_HD T falloff_exp(T x) {
  return hd::exp(hd::min(x, T(0)));
}

}  // namespace iesrgs::raster
