#pragma once
// The CPU kernels of each instruction-set variant (isa.hpp), between which kernels.hpp's
// project_forward, project_backward, blend_forward and blend_backward dispatch.
#include "raster/frame.hpp"

namespace iesrgs::raster::cpu {

template <typename T>
struct ProjectPasses {
  // project_forward and project_backward of kernels.hpp.
  void (*forward)(const GaussianParams<T>& g, const RasterCamera<T>& cam, Splat<T>* splats,
                  PixelRect* rects, int32_t* radii);
  void (*backward)(const GaussianParams<T>& g, const RasterCamera<T>& cam,
                   const SplatGrad<T>* splat_grads, const GaussianGrads<T>& grads);
};

template <typename T>
struct BlendPasses {
  // blend_forward and blend_backward of kernels.hpp, for a frame whose buffers are sized.
  void (*forward)(RasterFrame<T>& frame, T* image, T* alpha, T* depth);
  void (*backward)(RasterFrame<T>& frame, const T* dimage, const T* dalpha, const T* ddepth);
  int pack_bytes;  // SIMD width of the pixel loops
};

// Defined by the compilations of project.cpp and blend.cpp: the baseline ones always, the AVX2
// ones where IESRGS_CPU_AVX2_VARIANT is defined.
namespace baseline {
template <typename T>
ProjectPasses<T> project_passes();
template <typename T>
BlendPasses<T> blend_passes();
}  // namespace baseline
namespace avx2 {
template <typename T>
ProjectPasses<T> project_passes();
template <typename T>
BlendPasses<T> blend_passes();
}  // namespace avx2

}  // namespace iesrgs::raster::cpu
