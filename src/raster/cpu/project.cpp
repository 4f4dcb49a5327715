// Per-Gaussian projection, forward and backward, parallel over Gaussians.
#include "raster/project.hpp"

#include "raster/cpu/kernels.hpp"

namespace iesrgs::raster::cpu {

template <typename T>
void project_forward(const GaussianParams<T>& g, const RasterCamera<T>& cam, Splat<T>* splats,
                     PixelRect* rects, int32_t* radii) {
#pragma omp parallel for schedule(static)
  for (int i = 0; i < g.count; ++i) {
    Projection<T> p;
    rects[i] = {0, 0, 0, 0};
    radii[i] = 0;
    if (!project(g, i, cam, p)) continue;
    splats[i] = make_splat(g, i, cam, p);
    rects[i] = splat_rect(splats[i], p, cam.width, cam.height);
    if (!rects[i].empty()) radii[i] = splat_radius(splats[i], p);
  }
}

// A Gaussian outside the view, or hidden behind others wherever it falls, has all-zero partials
// and contributes nothing: skipping it saves recomputing its projection (most of the backward
// pass on small images, where many Gaussians are hidden).
template <typename T>
void project_backward(const GaussianParams<T>& g, const RasterCamera<T>& cam,
                      const SplatGrad<T>* splat_grads, const GaussianGrads<T>& grads) {
#pragma omp parallel for schedule(static)
  for (int i = 0; i < g.count; ++i)
    if (!splat_grads[i].is_zero()) project_backward(g, i, cam, splat_grads[i], grads);
}

template void project_forward(const GaussianParams<float>&, const RasterCamera<float>&,
                              Splat<float>*, PixelRect*, int32_t*);
template void project_forward(const GaussianParams<double>&, const RasterCamera<double>&,
                              Splat<double>*, PixelRect*, int32_t*);
template void project_backward(const GaussianParams<float>&, const RasterCamera<float>&,
                               const SplatGrad<float>*, const GaussianGrads<float>&);
template void project_backward(const GaussianParams<double>&, const RasterCamera<double>&,
                               const SplatGrad<double>*, const GaussianGrads<double>&);

}  // namespace iesrgs::raster::cpu
