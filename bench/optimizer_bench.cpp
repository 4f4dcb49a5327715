// Google Benchmark timings of the per-iteration bookkeeping around the rasterizer: the fused Adam
// step over every Gaussian parameter and the densification statistics of K rendered views.
#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include "gs/benchmark_model.hpp"
#include "gs/densify.hpp"
#include "gs/optimizer.hpp"
#include "timing.hpp"

namespace iesrgs::gs {
namespace {

// Through LibTorch, whose first operation on a thread would otherwise set OpenMP's thread count
// back to its own default (one thread with Debian's build).
void use_threads(int64_t threads) {
  torch::set_num_threads(int(threads));
}

// Args: Gaussians, OpenMP threads.
void BM_AdamStep(benchmark::State& state) {
  use_threads(state.range(1));
  GaussianModel model = benchmark_model(state.range(0));
  GaussianOptimizer optimizer(model, LearningRates{}, 4.0);
  for (auto _ : state) optimizer.step(model);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

// Args: Gaussians, views per iteration, OpenMP threads.
void BM_DensifyStatistics(benchmark::State& state) {
  use_threads(state.range(2));
  const int64_t n = state.range(0);
  DensifyStats stats = DensifyStats::zeros(n);
  std::vector<ViewStatistics> views;
  for (int64_t v = 0; v < state.range(1); ++v)
    views.push_back(
        {torch::randn({n, 2}), torch::rand({n, 2}), torch::randint(0, 20, {n}, torch::kInt32)});
  for (auto _ : state) stats.accumulate(views);
}

BENCHMARK(BM_AdamStep)
    ->ArgNames({"gaussians", "threads"})
    ->ArgsProduct({{100000, 500000}, {1, 2}})
    ->Apply(timed_in_wall_milliseconds);
BENCHMARK(BM_DensifyStatistics)
    ->ArgNames({"gaussians", "views", "threads"})
    ->ArgsProduct({{100000}, {1, 3}, {1, 2}})
    ->Apply(timed_in_wall_milliseconds);

}  // namespace
}  // namespace iesrgs::gs
