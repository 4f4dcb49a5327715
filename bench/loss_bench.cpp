#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstdint>
#include <vector>

#include "loss/ssim.hpp"

namespace iesrgs::loss {
namespace {

// Content does not change the cost; a fixed pattern keeps runs comparable.
std::vector<float> pattern(const ImageShape& shape, uint32_t seed) {
  std::vector<float> image(shape.values());
  for (size_t i = 0; i < image.size(); ++i)
    image[i] = float(((i + seed) * 2654435761u) >> 8) / 16777216.f;
  return image;
}

// Arguments: side (square RGB image), OpenMP threads.
struct SsimCase {
  ImageShape shape;
  std::vector<float> x, y;

  explicit SsimCase(const benchmark::State& state)
      : shape{int(state.range(0)), int(state.range(0)), 3},
        x(pattern(shape, 1)),
        y(pattern(shape, 2)) {
    omp_set_num_threads(int(state.range(1)));
  }
};

void BM_SsimForward(benchmark::State& state) {
  SsimCase c(state);
  std::vector<float> map(c.shape.pixels());
  for (auto _ : state)
    benchmark::DoNotOptimize(ssim<float>(c.x.data(), c.y.data(), c.shape, map.data(), nullptr));
  state.SetItemsProcessed(state.iterations() * int64_t(c.shape.pixels()));
}

// What a training step pays: the forward with partials, then the backward of the mean.
void BM_SsimForwardBackward(benchmark::State& state) {
  SsimCase c(state);
  std::vector<float> partials(ssim_partials_size(c.shape)), grad(c.shape.values());
  const std::vector<float> weight(c.shape.pixels(), 1.f / float(c.shape.pixels()));
  for (auto _ : state) {
    ssim<float>(c.x.data(), c.y.data(), c.shape, nullptr, partials.data());
    ssim_backward<float>(c.x.data(), c.y.data(), c.shape, partials.data(), weight.data(),
                         grad.data());
    benchmark::DoNotOptimize(grad.data());
  }
  state.SetItemsProcessed(state.iterations() * int64_t(c.shape.pixels()));
}

// HR views of the x4 protocol (800x800) and their LR inputs (200x200).
void ssim_sizes(benchmark::internal::Benchmark* b) {
  b->ArgNames({"side", "threads"});
  for (int side : {800, 200})
    for (int threads : {1, 2}) b->Args({side, threads});
}

BENCHMARK(BM_SsimForward)->Apply(ssim_sizes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SsimForwardBackward)->Apply(ssim_sizes)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace iesrgs::loss
