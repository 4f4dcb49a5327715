#include "raster/rasterizer.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "core/stopwatch.hpp"
#include "gs/sh.hpp"
#include "raster/cpu/kernels.hpp"

namespace iesrgs::raster {

template <typename T>
RasterCamera<T> raster_camera(const Camera& camera) {
  RasterCamera<T> c;
  const Intrinsics& k = camera.intrinsics;
  c.width = k.width;
  c.height = k.height;
  c.fx = T(k.fx);
  c.fy = T(k.fy);
  c.cx = T(k.cx);
  c.cy = T(k.cy);
  for (int i = 0; i < 9; ++i) c.rotation[i] = T(camera.rotation.m[i]);
  for (int i = 0; i < 3; ++i) c.translation[i] = T(camera.translation[i]);
  return c;
}

template <typename T>
void validate_inputs(const GaussianParams<T>& g, const RasterCamera<T>& cam) {
  if (cam.width <= 0 || cam.height <= 0)
    fail("rasterizer: image size {}x{} is not positive", cam.width, cam.height);
  if (!(cam.fx > 0 && cam.fy > 0))
    fail("rasterizer: focal lengths {} {} are not positive", cam.fx, cam.fy);
  if (g.count < 0) fail("rasterizer: negative Gaussian count {}", g.count);
  if (g.sh_degree < 0 || g.sh_degree > gs::kMaxShDegree)
    fail("rasterizer: SH degree {} is outside 0..{}", g.sh_degree, gs::kMaxShDegree);
  if (g.count > 0 &&
      !(g.means && g.log_scales && g.quats && g.opacity_logits && g.sh_dc && g.sh_rest))
    fail("rasterizer: a Gaussian parameter array is missing");
}

template <typename T>
void validate_targets(const RenderTargets<T>& out, int count) {
  if (!(out.image && out.alpha && out.depth && (out.radii || count == 0)))
    fail("rasterizer: every render target (image, alpha, depth, radii) is required");
}

template <typename T>
void validate_grads(const GaussianGrads<T>& grads, int count) {
  if (count > 0 && !(grads.means && grads.log_scales && grads.quats && grads.opacity_logits &&
                     grads.sh_dc && grads.sh_rest))
    fail("rasterizer: a parameter gradient array is missing");
}

template <typename T>
void rasterize_forward(const GaussianParams<T>& g, const RasterCamera<T>& cam,
                       const T background[3], RasterFrame<T>& frame, const RenderTargets<T>& out) {
  validate_inputs(g, cam);
  validate_targets(out, g.count);
  frame.camera = cam;
  std::copy_n(background, 3, frame.background);
  frame.splats.resize(g.count);
  frame.rects.resize(g.count);
  Stopwatch timer;
  cpu::project_forward(g, cam, frame.splats.data(), frame.rects.data(), out.radii);
  frame.timings.project = 1e3 * timer.lap();
  cpu::bin_splats(frame.splats.data(), frame.rects.data(), g.count, cam.width, cam.height,
                  frame.bins);
  frame.timings.bin = 1e3 * timer.lap();
  cpu::blend_forward(frame, out.image, out.alpha, out.depth);
  frame.timings.blend = 1e3 * timer.lap();
}

template <typename T>
void rasterize_backward(const GaussianParams<T>& g, RasterFrame<T>& frame,
                        const PixelGrads<T>& pixel_grads, const GaussianGrads<T>& grads) {
  if (size_t(g.count) != frame.splats.size())
    fail("rasterizer: backward got {} Gaussians, forward rendered {}", g.count,
         frame.splats.size());
  validate_grads(grads, g.count);
  Stopwatch timer;
  cpu::blend_backward(frame, pixel_grads.image, pixel_grads.alpha, pixel_grads.depth);
  frame.timings.blend_backward = 1e3 * timer.lap();
  cpu::project_backward(g, frame.camera, frame.splat_grads.data(), grads);
  frame.timings.project_backward = 1e3 * timer.lap();
}

template RasterCamera<float> raster_camera(const Camera&);
template RasterCamera<double> raster_camera(const Camera&);
template void validate_inputs(const GaussianParams<float>&, const RasterCamera<float>&);
template void validate_inputs(const GaussianParams<double>&, const RasterCamera<double>&);
template void validate_targets(const RenderTargets<float>&, int);
template void validate_targets(const RenderTargets<double>&, int);
template void validate_grads(const GaussianGrads<float>&, int);
template void validate_grads(const GaussianGrads<double>&, int);
template void rasterize_forward(const GaussianParams<float>&, const RasterCamera<float>&,
                                const float[3], RasterFrame<float>&, const RenderTargets<float>&);
template void rasterize_forward(const GaussianParams<double>&, const RasterCamera<double>&,
                                const double[3], RasterFrame<double>&,
                                const RenderTargets<double>&);
template void rasterize_backward(const GaussianParams<float>&, RasterFrame<float>&,
                                 const PixelGrads<float>&, const GaussianGrads<float>&);
template void rasterize_backward(const GaussianParams<double>&, RasterFrame<double>&,
                                 const PixelGrads<double>&, const GaussianGrads<double>&);

}  // namespace iesrgs::raster
