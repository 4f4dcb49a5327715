#pragma once
// The CPU kernels of each instruction-set variant (core/cpu_isa_variant.hpp), between which
// kernels.hpp's projection and blend passes dispatch.
#include "raster/frame.hpp"
#include "raster/project.hpp"

namespace iesrgs::raster::cpu {

// The projection of a pack of Gaussians in SIMD lanes, float only (raster/cpu/project.cpp runs
// the loops around it).
struct ProjectPacks {
  // Gaussians index[0..lanes) of g: their splats, their pixel bounds, and whether each is
  // visible (the others' splats and bounds are undefined).
  void (*forward)(const GaussianParams<float>& g, const RasterCamera<float>& cam, const int* index,
                  Splat<float>* splats, SplatBounds<float>* bounds, bool* visible);
  // Their gradients from the gradients of their splats, and whether each is visible (the others
  // get none).
  void (*backward)(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                   const SplatGrad<float>* splat_grads, const int* index,
                   GaussianRowGrad<float>* grads, bool* visible);
  int lanes;  // Gaussians per pack
};

// The packs of the variant cpu_isa::active() names (dispatch.cpp).
ProjectPacks active_project_packs();

template <typename T>
struct BlendPasses {
  // blend_forward and blend_backward of kernels.hpp, for a frame whose buffers are sized.
  void (*forward)(RasterFrame<T>& frame, T* image, T* alpha, T* depth);
  void (*backward)(RasterFrame<T>& frame, const T* dimage, const T* dalpha, const T* ddepth);
  int pack_bytes;  // SIMD width of the pixel loops
};

// Defined by the compilations of project_packs.cpp and blend.cpp: the baseline ones always, the
// AVX2 ones where IESRGS_CPU_AVX2_VARIANT is defined.
namespace baseline {
ProjectPacks project_packs();
template <typename T>
BlendPasses<T> blend_passes();
}  // namespace baseline
namespace avx2 {
ProjectPacks project_packs();
template <typename T>
BlendPasses<T> blend_passes();
}  // namespace avx2

}  // namespace iesrgs::raster::cpu
