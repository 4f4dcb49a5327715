#pragma once
// The blend passes of each instruction-set variant (isa.hpp), between which kernels.hpp's
// blend_forward and blend_backward dispatch.
#include "raster/frame.hpp"

namespace iesrgs::raster::cpu {

template <typename T>
struct BlendPasses {
  // blend_forward and blend_backward of kernels.hpp, for a frame whose buffers are sized.
  void (*forward)(RasterFrame<T>& frame, T* image, T* alpha, T* depth);
  void (*backward)(RasterFrame<T>& frame, const T* dimage, const T* dalpha, const T* ddepth);
  int pack_bytes;  // SIMD width of the pixel loops
};

// Defined by the compilations of blend.cpp: the baseline one always, the AVX2 one where
// IESRGS_CPU_AVX2_VARIANT is defined.
namespace baseline {
template <typename T>
BlendPasses<T> blend_passes();
}  // namespace baseline
namespace avx2 {
template <typename T>
BlendPasses<T> blend_passes();
}  // namespace avx2

}  // namespace iesrgs::raster::cpu
