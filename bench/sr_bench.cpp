#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <string>

#include "core/error.hpp"
#include "priors/sr/registry.hpp"
#include "priors/sr/sr_net.hpp"
#include "priors/sr/tiling.hpp"
#include "timing.hpp"

namespace iesrgs {
namespace {

using priors::sr::SrNet;

// A fixed pseudo-random image: content does not change the cost.
torch::Tensor input(int64_t height, int64_t width) {
  torch::manual_seed(0);
  return torch::rand({1, 3, height, width});
}

// One x4 upscale of a 200x200 image to 800x800 (the LR size of the benchmark protocol), with
// the model's default checkpoint; skipped when that is not available.
void upscale_case(benchmark::State& state, const std::string& model, int tile) {
  torch::set_num_threads(int(state.range(0)));  // LibTorch sets OpenMP's thread count
  std::unique_ptr<SrNet> net;
  try {
    net = priors::sr::make_sr_net(model, {}, 4);
  } catch (const Error& e) {
    state.SkipWithError(e.what());
    return;
  }
  const torch::Tensor image = input(200, 200);
  priors::sr::upscale_tiled(*net, image, {tile, 32});  // untimed: oneDNN sets up on its first call
  for (auto _ : state) benchmark::DoNotOptimize(priors::sr::upscale_tiled(*net, image, {tile, 32}));
  state.SetItemsProcessed(state.iterations());
}

void BM_SrBicubic200To800(benchmark::State& state) {
  upscale_case(state, "bicubic", 0);
}
void BM_SrSafmn200To800(benchmark::State& state) {
  upscale_case(state, "safmn", 0);
}
void BM_SrImdn200To800(benchmark::State& state) {
  upscale_case(state, "imdn", 0);
}
void BM_SrPan200To800(benchmark::State& state) {
  upscale_case(state, "pan", 0);
}
// The same in 4 tiles of 128 with the default overlap: the price of tiling.
void BM_SrPan200To800Tiled128(benchmark::State& state) {
  upscale_case(state, "pan", 128);
}

BENCHMARK(BM_SrBicubic200To800)->Apply(on_machine_threads);
BENCHMARK(BM_SrSafmn200To800)->Apply(on_machine_threads);
BENCHMARK(BM_SrImdn200To800)->Apply(on_machine_threads);
BENCHMARK(BM_SrPan200To800)->Apply(on_machine_threads);
BENCHMARK(BM_SrPan200To800Tiled128)->Apply(on_machine_threads);

}  // namespace
}  // namespace iesrgs
