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

namespace iesrgs::hd {

#if defined(__CUDACC__)
using ::ceil;
using ::exp;
using ::floor;
using ::isfinite;
using ::log;
using ::sqrt;
#else
using std::ceil;
using std::exp;
using std::floor;
using std::isfinite;
using std::log;
using std::sqrt;
#endif

template <typename T>
IESRGS_HD T min(T a, T b) {
  return b < a ? b : a;
}
template <typename T>
IESRGS_HD T max(T a, T b) {
  return a < b ? b : a;
}

}  // namespace iesrgs::hd
