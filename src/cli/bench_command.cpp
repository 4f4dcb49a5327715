// iesrgs bench raster: times the CPU rasterizer on a synthetic scene (forward, forward+backward,
// and the cost of each stage).
#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <vector>

#include "cli/commands.hpp"
#include "core/error.hpp"
#include "gs/sh.hpp"
#include "raster/cpu/dispatch.hpp"
#include "raster/rasterizer.hpp"
#include "raster/synthetic_scene.hpp"

namespace iesrgs::cli {

namespace {

struct RasterBenchArgs {
  int gaussians = 100000;
  int width = 800, height = 800;
  int threads = 0;  // 0: OpenMP's default
  int iterations = 5;
};

double elapsed_ms(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since)
      .count();
}

void run_raster_bench(const RasterBenchArgs& args) {
  if (args.gaussians < 0 || args.width <= 0 || args.height <= 0 || args.iterations <= 0 ||
      args.threads < 0)
    fail(
        "bench raster: --width, --height and --iterations must be positive, --gaussians and "
        "--threads not negative");
  if (args.threads > 0) omp_set_num_threads(args.threads);
  using namespace raster;
  const RasterCamera<float> cam = benchmark_camera(args.width, args.height);
  const GaussianCloud cloud = synthetic_scene(args.gaussians, cam, 1);
  const GaussianParams<float> g = cloud.params();
  const size_t plane = size_t(args.width) * args.height, n = size_t(args.gaussians);
  std::vector<float> image(3 * plane), alpha(plane), depth(plane);
  std::vector<int32_t> radii(n);
  // A loss gradient that reaches every output.
  const std::vector<float> dimage(3 * plane, 1e-3f), dalpha(plane, 1e-3f), ddepth(plane, 1e-4f);
  std::vector<float> dmeans(3 * n), dscales(3 * n), dquats(4 * n), dlogits(n),
      dsh(3 * gs::kShCoefficients * n), dview(2 * n), dview_abs(2 * n);
  const float background[3] = {1, 1, 1};
  RasterFrame<float> frame;
  std::vector<double> forward, total, cpu, project, bin, blend, backward;
  // One warm-up pass sizes every buffer.
  for (int it = -1; it < args.iterations; ++it) {
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    rasterize_forward(g, cam, background, frame,
                      RenderTargets<float>{image.data(), alpha.data(), depth.data(), radii.data()});
    const double forward_ms = elapsed_ms(start);
    rasterize_backward(
        g, frame, PixelGrads<float>{dimage.data(), dalpha.data(), ddepth.data()},
        GaussianGrads<float>{dmeans.data(), dscales.data(), dquats.data(), dlogits.data(),
                             dsh.data(), dview.data(), dview_abs.data()});
    if (it < 0) continue;
    forward.push_back(forward_ms);
    total.push_back(elapsed_ms(start));
    cpu.push_back(1000.0 * double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
    project.push_back(frame.timings.project);
    bin.push_back(frame.timings.bin);
    blend.push_back(frame.timings.blend);
    backward.push_back(frame.timings.blend_backward + frame.timings.project_backward);
  }
  const size_t drawn =
      size_t(std::count_if(radii.begin(), radii.end(), [](int r) { return r > 0; }));
  fmt::print(
      "scene: {} Gaussians ({} drawn), {}x{}, {} tile entries, {} threads, {} iterations "
      "(medians)\n",
      n, drawn, args.width, args.height, frame.bins.entry_count(), omp_get_max_threads(),
      args.iterations);
  fmt::print("blend kernels: {}\n", cpu::describe_isa(cpu::active_isa()));
  // Medians over iterations, so one disturbed run (a shared machine) does not skew a stage.
  fmt::print("forward: {:.1f} ms\n", median(forward));
  fmt::print("forward+backward: {:.1f} ms\n", median(total));
  fmt::print("  projection: {:.1f} ms\n", median(project));
  fmt::print("  binning/sort: {:.1f} ms\n", median(bin));
  fmt::print("  blend: {:.1f} ms\n", median(blend));
  fmt::print("  backward: {:.1f} ms\n", median(backward));
  // On a busy machine wall time overstates the cost; CPU time (summed over threads) does not.
  fmt::print("cpu time, forward+backward: {:.1f} ms over all threads\n", median(cpu));
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto* bench = app.add_subcommand("bench", "Time parts of the system on synthetic inputs");
  bench->require_subcommand(1);
  auto* raster = bench->add_subcommand("raster", "Time the CPU rasterizer, forward and backward");
  auto args = std::make_shared<RasterBenchArgs>();
  raster->add_option("--gaussians", args->gaussians, "Number of Gaussians")->capture_default_str();
  raster->add_option("--width", args->width, "Image width")->capture_default_str();
  raster->add_option("--height", args->height, "Image height")->capture_default_str();
  raster->add_option("--threads", args->threads, "OpenMP threads (default: all cores)");
  raster->add_option("--iterations", args->iterations, "Timed iterations")->capture_default_str();
  raster->callback([args] { run_raster_bench(*args); });
}

}  // namespace iesrgs::cli
