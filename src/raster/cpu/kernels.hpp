#pragma once
// CPU kernels of the rasterizer, one stage per file; OpenMP inside, deterministic results.
#include "raster/frame.hpp"

namespace iesrgs::raster::cpu {

// Splats, pixel rectangles and radii of every Gaussian (culled ones get an empty rect, radius 0).
template <typename T>
void project_forward(const GaussianParams<T>& g, const RasterCamera<T>& cam, Splat<T>* splats,
                     PixelRect* rects, int32_t* radii);
// Overwrites grads with the parameter gradients of every Gaussian from the per-splat gradients.
// In float, both projection passes run the active instruction-set variant (cpu_isa::active(),
// dispatched in dispatch.cpp); in double, the plain scalar code.
template <typename T>
void project_backward(const GaussianParams<T>& g, const RasterCamera<T>& cam,
                      const SplatGrad<T>* splat_grads, const GaussianGrads<T>& grads);

// Lists the tiles each splat's rectangle touches, grouped by tile and sorted by depth.
template <typename T>
void bin_splats(const Splat<T>* splats, const PixelRect* rects, int count, int width, int height,
                TileBins& bins);

// Front-to-back blending of every tile; fills the frame's per-pixel state for the backward pass.
// image (3, H, W), alpha and depth (H, W); depth is the alpha-blended camera z. Both blend passes
// run the active instruction-set variant (dispatched in dispatch.cpp).
template <typename T>
void blend_forward(RasterFrame<T>& frame, T* image, T* alpha, T* depth);
// Back-to-front pass over every tile: per-entry partial gradients, reduced into
// frame.splat_grads. Any of the pixel gradients may be null (zero).
template <typename T>
void blend_backward(RasterFrame<T>& frame, const T* dimage, const T* dalpha, const T* ddepth);

}  // namespace iesrgs::raster::cpu
