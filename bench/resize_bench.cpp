#include <benchmark/benchmark.h>

#include <omp.h>

#include <cstdint>

#include "io/resize.hpp"
#include "timing.hpp"

namespace iesrgs {
namespace {

// Content does not change the cost; a fixed pattern keeps runs comparable.
Image8 pattern(int width, int height, int channels) {
  Image8 image(width, height, channels);
  for (size_t i = 0; i < image.data.size(); ++i) image.data[i] = uint8_t((i * 2654435761u) >> 24);
  return image;
}

void resize_case(benchmark::State& state, int width, int height, int channels, int out_width,
                 int out_height) {
  omp_set_num_threads(int(state.range(0)));
  const Image8 source = pattern(width, height, channels);
  for (auto _ : state) benchmark::DoNotOptimize(resize_bicubic(source, out_width, out_height));
  state.SetItemsProcessed(state.iterations() * int64_t(width) * height);
}

// LR inputs of the x4 benchmark protocol (nerf_synthetic views).
void BM_ResizeRgba800To200(benchmark::State& state) {
  resize_case(state, 800, 800, 4, 200, 200);
}
// Halving a real capture (fox views are 1080x1920).
void BM_ResizeRgb1080x1920To540x960(benchmark::State& state) {
  resize_case(state, 1080, 1920, 3, 540, 960);
}
// The bicubic x4 SR baseline.
void BM_ResizeRgba200To800(benchmark::State& state) {
  resize_case(state, 200, 200, 4, 800, 800);
}

BENCHMARK(BM_ResizeRgba800To200)->Apply(on_machine_threads);
BENCHMARK(BM_ResizeRgb1080x1920To540x960)->Apply(on_machine_threads);
BENCHMARK(BM_ResizeRgba200To800)->Apply(on_machine_threads);

}  // namespace
}  // namespace iesrgs
