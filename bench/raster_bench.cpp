// Google Benchmark timings of the CPU rasterizer on the synthetic scene of `iesrgs bench raster`.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <vector>

#include "raster/rasterizer.hpp"
#include "raster/synthetic_scene.hpp"
#include "timing.hpp"

namespace iesrgs::raster {
namespace {

// Everything one frame needs, sized for a scene and image.
struct BenchFrame {
  RasterCamera<float> camera;
  GaussianCloud cloud;
  HostFrameBuffers buffers;
  std::vector<float> pixel_grad;
  RasterFrame<float> frame;
  const float background[3] = {1, 1, 1};

  BenchFrame(int gaussians, int width, int height)
      : camera(benchmark_camera(width, height)),
        cloud(synthetic_scene(gaussians, camera, 1)),
        buffers(size_t(width) * height, size_t(gaussians)),
        pixel_grad(3 * size_t(width) * height, 1e-3f) {}
  void forward() {
    rasterize_forward(cloud.params(), camera, background, frame, buffers.targets());
  }
  void backward() {
    // The color gradient's first plane doubles as the alpha and depth gradients. The viewspace
    // gradients are asked for as training asks for them, for densification.
    rasterize_backward(cloud.params(), frame,
                       PixelGrads<float>{pixel_grad.data(), pixel_grad.data(), pixel_grad.data()},
                       buffers.gaussian_grads());
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
