// Per-Gaussian projection, forward and backward, parallel over Gaussians. Float runs packs of
// Gaussians in SIMD lanes (project_packs.cpp, in the active instruction-set variant), with the
// results of the scalar code to the bit; double, for the gradient checks, runs the scalar
// formulas of raster/project.hpp one Gaussian at a time.
#include <algorithm>
#include <type_traits>

#include "raster/cpu/kernels.hpp"
#include "raster/cpu/variants.hpp"
#include "raster/rasterizer.hpp"

namespace iesrgs::raster::cpu {

namespace {

constexpr int kMaxLanes = 16;  // room for any variant's pack

// Lane indices for Gaussians first..first + lanes, the last one repeated past count.
void lane_indices(int first, int lanes, int count, int* index) {
  for (int l = 0; l < lanes; ++l) index[l] = std::min(first + l, count - 1);
}

// Gaussians per block of the backward pass, whose ones with a gradient are packed into lanes.
constexpr int kBackwardBlock = 256;

void forward_packs(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                   Splat<float>* splats, PixelRect* rects, int32_t* radii) {
  const ProjectPacks packs = active_project_packs();
  const int count = (g.count + packs.lanes - 1) / packs.lanes;
#pragma omp parallel for schedule(static)
  for (int pack = 0; pack < count; ++pack) {
    const int first = pack * packs.lanes;
    int index[kMaxLanes];
    Splat<float> splat[kMaxLanes];
    SplatBounds<float> bounds[kMaxLanes];
    bool visible[kMaxLanes];
    lane_indices(first, packs.lanes, g.count, index);
    packs.forward(g, cam, index, splat, bounds, visible);
    for (int l = 0; l < packs.lanes && first + l < g.count; ++l) {
      const int i = first + l;
      splat_rect(visible[l], bounds[l], rects[i], radii[i]);
      if (visible[l]) splats[i] = splat[l];
    }
  }
}

void forward_rows(const GaussianParams<double>& g, const RasterCamera<double>& cam,
                  Splat<double>* splats, PixelRect* rects, int32_t* radii) {
#pragma omp parallel for schedule(static)
  for (int i = 0; i < g.count; ++i) {
    Projection<double> p;
    rects[i] = {0, 0, 0, 0};
    radii[i] = 0;
    if (!project(g, i, cam, p)) continue;
    splats[i] = make_splat(g, i, cam, p);
    splat_rect(splats[i], p.filtered, cam.width, cam.height, rects[i], radii[i]);
  }
}

// A Gaussian outside the view, or hidden behind others wherever it falls, has all-zero partials
// and contributes nothing: skipping it saves recomputing its projection (most of the backward
// pass on small images, where many Gaussians are hidden). Each block clears its Gaussians'
// gradients first, in parallel and while they are about to be written.
void backward_packs(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                    const SplatGrad<float>* splat_grads, const GaussianGrads<float>& grads) {
  const ProjectPacks packs = active_project_packs();
  const int blocks = (g.count + kBackwardBlock - 1) / kBackwardBlock;
#pragma omp parallel for schedule(static)
  for (int block = 0; block < blocks; ++block) {
    int live[kBackwardBlock + kMaxLanes];
    int n = 0;
    const int end = std::min(g.count, (block + 1) * kBackwardBlock);
    clear_grads(grads, size_t(g.count), size_t(block) * kBackwardBlock, size_t(end));
    for (int i = block * kBackwardBlock; i < end; ++i)
      if (!splat_grads[i].is_zero()) live[n++] = i;
    for (int start = 0; start < n; start += packs.lanes) {
      const int used = std::min(packs.lanes, n - start);
      for (int l = used; l < packs.lanes; ++l) live[start + l] = live[start + used - 1];
      GaussianRowGrad<float> d[kMaxLanes];
      bool visible[kMaxLanes];
      packs.backward(g, cam, splat_grads, live + start, d, visible);
      for (int l = 0; l < used; ++l)
        if (visible[l]) add_row_grad(d[l], live[start + l], grads);
    }
  }
}

void backward_rows(const GaussianParams<double>& g, const RasterCamera<double>& cam,
                   const SplatGrad<double>* splat_grads, const GaussianGrads<double>& grads) {
#pragma omp parallel for schedule(static)
  for (int i = 0; i < g.count; ++i) {
    clear_grads(grads, size_t(g.count), size_t(i), size_t(i) + 1);
    if (!splat_grads[i].is_zero()) project_backward(g, i, cam, splat_grads[i], grads);
  }
}

}  // namespace

template <typename T>
void project_forward(const GaussianParams<T>& g, const RasterCamera<T>& cam, Splat<T>* splats,
                     PixelRect* rects, int32_t* radii) {
  if constexpr (std::is_same_v<T, float>)
    forward_packs(g, cam, splats, rects, radii);
  else
    forward_rows(g, cam, splats, rects, radii);
}

template <typename T>
void project_backward(const GaussianParams<T>& g, const RasterCamera<T>& cam,
                      const SplatGrad<T>* splat_grads, const GaussianGrads<T>& grads) {
  if constexpr (std::is_same_v<T, float>)
    backward_packs(g, cam, splat_grads, grads);
  else
    backward_rows(g, cam, splat_grads, grads);
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
