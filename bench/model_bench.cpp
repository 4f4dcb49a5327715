// Google Benchmark timing of the starting model's scales: the mean squared distance of each
// starting point to its three nearest neighbours, for a box of random points with and without one
// far outlier (SfM clouds have them).
#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include <random>
#include <vector>

#include "gs/neighbors.hpp"
#include "timing.hpp"

namespace iesrgs::gs {
namespace {

// Args: points, how far the outlier lies in box sizes (0: none), OpenMP threads.
void BM_StartingScales(benchmark::State& state) {
  torch::set_num_threads(int(state.range(2)));  // LibTorch sets OpenMP's thread count
  const int count = int(state.range(0));
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> uniform(-1, 1);
  std::vector<float> points(3 * size_t(count));
  for (float& value : points) value = uniform(rng);
  if (state.range(1) > 0) points[0] = float(state.range(1));
  for (auto _ : state)
    benchmark::DoNotOptimize(mean_knn_squared_distance(points.data(), count).data());
  state.SetItemsProcessed(state.iterations() * count);
}

BENCHMARK(BM_StartingScales)
    ->ArgNames({"points", "outlier", "threads"})
    ->ArgsProduct({{100000}, {0, 100}, {2}})
    ->Apply(timed_in_wall_milliseconds);

}  // namespace
}  // namespace iesrgs::gs
