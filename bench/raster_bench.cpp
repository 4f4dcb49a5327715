// Google Benchmark timings of the CPU rasterizer on the synthetic scene of `iesrgs bench raster`.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <vector>

#include "gs/sh.hpp"
#include "raster/rasterizer.hpp"
#include "raster/synthetic_scene.hpp"
#include "timing.hpp"

namespace iesrgs::raster {
namespace {

// Everything one frame needs, sized for a scene and image.
struct BenchFrame {
  RasterCamera<float> camera;
  GaussianCloud cloud;
  std::vector<float> image, alpha, depth, pixel_grad;
  std::vector<int32_t> radii;
  std::vector<float> dmeans, dscales, dquats, dlogits, dsh_dc, dsh_rest, dview, dview_abs;
  RasterFrame<float> frame;
  const float background[3] = {1, 1, 1};

  BenchFrame(int gaussians, int width, int height)
      : camera(benchmark_camera(width, height)), cloud(synthetic_scene(gaussians, camera, 1)) {
    const size_t plane = size_t(width) * height, n = size_t(gaussians);
    image.resize(3 * plane);
    alpha.resize(plane);
    depth.resize(plane);
    pixel_grad.assign(3 * plane, 1e-3f);
    radii.resize(n);
    dmeans.resize(3 * n);
    dscales.resize(3 * n);
    dquats.resize(4 * n);
    dlogits.resize(n);
    dsh_dc.resize(3 * n);
    dsh_rest.resize(gs::kShRestFloats * n);
    dview.resize(2 * n);
    dview_abs.resize(2 * n);
  }
  void forward() {
    rasterize_forward(cloud.params(), camera, background, frame,
                      RenderTargets<float>{image.data(), alpha.data(), depth.data(), radii.data()});
  }
  void backward() {
    // The color gradient's first plane doubles as the alpha and depth gradients. The viewspace
    // gradients are asked for as training asks for them, for densification.
    rasterize_backward(
        cloud.params(), frame,
        PixelGrads<float>{pixel_grad.data(), pixel_grad.data(), pixel_grad.data()},
        GaussianGrads<float>{dmeans.data(), dscales.data(), dquats.data(), dlogits.data(),
                             dsh_dc.data(), dsh_rest.data(), dview.data(), dview_abs.data()});
  }
};

// Args: Gaussians, image side, OpenMP threads.
void BM_RasterForward(benchmark::State& state) {
  omp_set_num_threads(int(state.range(2)));
  BenchFrame f(int(state.range(0)), int(state.range(1)), int(state.range(1)));
  for (auto _ : state) f.forward();
}

void BM_RasterForwardBackward(benchmark::State& state) {
  omp_set_num_threads(int(state.range(2)));
  BenchFrame f(int(state.range(0)), int(state.range(1)), int(state.range(1)));
  for (auto _ : state) {
    f.forward();
    f.backward();
  }
}

BENCHMARK(BM_RasterForward)
    ->Args({100000, 800, 1})
    ->Args({100000, 800, 2})
    ->Apply(timed_in_wall_milliseconds);
BENCHMARK(BM_RasterForwardBackward)
    ->Args({100000, 800, 1})
    ->Args({100000, 800, 2})
    ->Apply(timed_in_wall_milliseconds);

}  // namespace
}  // namespace iesrgs::raster
