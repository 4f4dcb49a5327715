#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include <torch/torch.h>

#include "core/math.hpp"
#include "loss/autograd.hpp"
#include "loss/benchmark_image.hpp"
#include "loss/photometric.hpp"
#include "loss/ssim.hpp"
#include "loss/texture_fusion.hpp"
#include "timing.hpp"

namespace iesrgs::loss {
namespace {

// Arguments: side (square RGB image), OpenMP threads.
struct SsimCase {
  ImageShape shape;
  std::vector<float> x, y;

  explicit SsimCase(const benchmark::State& state)
      : shape{int(state.range(0)), int(state.range(0)), 3},
        x(benchmark_image(shape, 1)),
        y(benchmark_image(shape, 2)) {
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

// HR views of the x4 protocol (800x800) and their LR inputs (200x200), and the HR views of the
// CPU-scale runs (400x400), where the texture loss below runs.
void ssim_sizes(benchmark::internal::Benchmark* b) {
  b->ArgNames({"side", "threads"});
  for (int side : {800, 400, 200})
    for (int threads : {1, 2}) b->Args({side, threads});
}

BENCHMARK(BM_SsimForward)->Apply(ssim_sizes)->Apply(timed_in_wall_milliseconds);
BENCHMARK(BM_SsimForwardBackward)->Apply(ssim_sizes)->Apply(timed_in_wall_milliseconds);

// A mask like IE-SRGS's M on lego at x4: thin broken outlines (every 4th pixel of a dozen circles
// in the middle of the view), about 0.5 % of the pixels.
std::vector<float> outline_mask(const ImageShape& shape) {
  std::vector<float> mask(shape.pixels(), 0.f);
  const double side = shape.width;
  for (int circle = 0; circle < 12; ++circle) {
    const double cx = side * (0.3 + 0.4 * ((circle * 7) % 12) / 11.0);
    const double cy = side * (0.3 + 0.4 * ((circle * 5) % 12) / 11.0);
    const double radius = side * (0.05 + 0.15 * ((circle * 3) % 12) / 11.0);
    const int points = int(2 * kPi * radius);
    for (int k = 0; k < points; k += 4) {
      const int x = int(cx + radius * std::cos(2 * kPi * k / points));
      const int y = int(cy + radius * std::sin(2 * kPi * k / points));
      if (x >= 0 && x < shape.width && y >= 0 && y < shape.height)
        mask[size_t(y) * shape.width + x] = 1.f;
    }
  }
  return mask;
}

// One fusion step's texture loss with its gradient: against E alone (share 0, the external-only
// row) or mask-guided (Arguments: side, threads, masked).
void BM_GuidedTexture(benchmark::State& state) {
  SsimCase c(state);
  const std::vector<float> render = benchmark_image(c.shape, 3);
  const std::vector<float> share =
      state.range(2) ? outline_mask(c.shape) : std::vector<float>(c.shape.pixels(), 0.f);
  std::vector<float> grad(c.shape.values());
  for (auto _ : state)
    benchmark::DoNotOptimize(guided_texture_loss(render.data(), c.x.data(), c.y.data(),
                                                 share.data(), c.shape, kDssimWeight, grad.data()));
  const SsimSupport support = ssim_support(share.data(), c.shape);
  state.counters["tiles"] = double(support.weighted.size()) / double(support.tiles);
}

BENCHMARK(BM_GuidedTexture)
    ->ArgNames({"side", "threads", "masked"})
    ->ArgsProduct({{400, 800}, {1, 2}, {0, 1}})
    ->Apply(timed_in_wall_milliseconds);

// The internal depth term of a fusion step with its gradients, as the hand-written kernel
// (`ops:0`) or as the tensor ops that GPUs run (`ops:1`), at 400x400: a render covering about
// 58 % of the pixels, a reference with holes.
void BM_InternalDepthTerm(benchmark::State& state) {
  torch::manual_seed(0);
  omp_set_num_threads(2);
  torch::set_num_threads(2);
  const int64_t side = 400;
  const at::Tensor alpha = (1.2 * torch::rand({side, side})).clamp_max(1).requires_grad_(true);
  const at::Tensor depth =
      (alpha.detach() * (1 + 4 * torch::rand({side, side}))).requires_grad_(true);
  const at::Tensor reference = 4 * torch::rand({side, side}) * (torch::rand({side, side}) > 0.2);
  for (auto _ : state) {
    const at::Tensor l1 = state.range(0) ? covered_depth_l1_from_ops(depth, alpha, reference)
                                         : covered_depth_l1_autograd(depth, alpha, reference);
    (1e-3 * l1).backward();
    alpha.mutable_grad() = at::Tensor();
    depth.mutable_grad() = at::Tensor();
  }
}

BENCHMARK(BM_InternalDepthTerm)->ArgName("ops")->Arg(0)->Arg(1)->Apply(timed_in_wall_milliseconds);

}  // namespace
}  // namespace iesrgs::loss
