#pragma once
// Per-pixel evaluation of a splat, shared by the forward and backward blending kernels. The
// functions are templated on the value type V as well, so that the CPU kernels can evaluate four
// pixels at once with SIMD packs.
#include "raster/project.hpp"

namespace iesrgs::raster {

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
