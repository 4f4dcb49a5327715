#pragma once
// The raster math headers are compiled both by the host compiler and by nvcc for the CUDA
// kernels: every function is marked IESRGS_HD, uses plain structs and raw arrays only, and reaches
// the math library through iesrgs::hd so that device code gets the CUDA overloads.
#include <cmath>

#if defined(__CUDACC__)
#define IESRGS_HD __host__ __device__ inline
#else
#define IESRGS_HD inline
#endif
// Inlined at every optimization level, for the functions that an instruction-set variant of the
// CPU kernels calls with plain scalars: a copy of its own would share the baseline's name
// (core/cpu_isa_variant.hpp).
#if defined(__CUDACC__)
#define IESRGS_HD_ALWAYS_INLINE __host__ __device__ __forceinline__
#else
#define IESRGS_HD_ALWAYS_INLINE inline __attribute__((always_inline))
#endif

namespace iesrgs::hd {

// The math functions are templates so that the CPU kernels can specialize them for their SIMD
// lanes (raster/cpu/lanes.hpp) and run the same formulas on several Gaussians at once.
#if defined(__CUDACC__)
#define IESRGS_HD_LIBM ::
#else
#define IESRGS_HD_LIBM std::
#endif
#define IESRGS_HD_MATH(name)       \
  template <typename T>            \
  IESRGS_HD T name(T x) {          \
    return IESRGS_HD_LIBM name(x); \
  }
IESRGS_HD_MATH(ceil)
IESRGS_HD_MATH(floor)
IESRGS_HD_MATH(exp)
IESRGS_HD_MATH(log)
IESRGS_HD_MATH(sqrt)
#undef IESRGS_HD_MATH
#undef IESRGS_HD_LIBM

template <typename T>
IESRGS_HD T min(T a, T b) {
  return b < a ? b : a;
}
template <typename T>
IESRGS_HD T max(T a, T b) {
  return a < b ? b : a;
}

// What comparing two T gives: bool for scalars, a lane mask for SIMD packs.
template <typename T>
using Mask = decltype(T() < T());

// a where cond holds, else b; without branching on packs.
template <typename T>
IESRGS_HD T select(Mask<T> cond, T a, T b) {
  return cond ? a : b;
}

}  // namespace iesrgs::hd
