// Per-Gaussian projection on the GPU, forward and backward, one thread per Gaussian: the same
// functions as the CPU kernels (raster/project.hpp).
#include "raster/cuda/kernels.cuh"
#include "raster/project.hpp"
#include "raster/tiles.hpp"

namespace iesrgs::raster::cuda {

namespace {

constexpr int kThreads = 256;

__global__ void project_forward_kernel(GaussianParams<float> g, RasterCamera<float> cam,
                                       Splat<float>* splats, PixelRect* rects, int32_t* radii,
                                       uint64_t* tiles_touched) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= g.count) return;
  Projection<float> p;
  PixelRect rect{0, 0, 0, 0};
  int32_t radius = 0;
  if (project(g, i, cam, p)) {
    const Splat<float> s = make_splat(g, i, cam, p);
    splats[i] = s;
    splat_rect(s, p.filtered, cam.width, cam.height, rect, radius);
  }
  rects[i] = rect;
  radii[i] = radius;
  tiles_touched[i] = tiles_of(rect).count();
}

// A Gaussian outside the view, or hidden wherever it falls, has all-zero partials: skipped, as on
// the CPU.
__global__ void project_backward_kernel(GaussianParams<float> g, RasterCamera<float> cam,
                                        const SplatGrad<float>* splat_grads,
                                        GaussianGrads<float> grads) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= g.count) return;
  const SplatGrad<float> ds = splat_grads[i];
  if (!ds.is_zero()) project_backward(g, i, cam, ds, grads);
}

}  // namespace

void project_forward(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                     Splat<float>* splats, PixelRect* rects, int32_t* radii,
                     uint64_t* tiles_touched, cudaStream_t stream) {
  if (g.count == 0) return;
  project_forward_kernel<<<blocks_for(g.count, kThreads), kThreads, 0, stream>>>(
      g, cam, splats, rects, radii, tiles_touched);
  check(cudaGetLastError(), "project_forward");
}

void project_backward(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                      const SplatGrad<float>* splat_grads, const GaussianGrads<float>& grads,
                      cudaStream_t stream) {
  if (g.count == 0) return;
  project_backward_kernel<<<blocks_for(g.count, kThreads), kThreads, 0, stream>>>(
      g, cam, splat_grads, grads);
  check(cudaGetLastError(), "project_backward");
}

}  // namespace iesrgs::raster::cuda
