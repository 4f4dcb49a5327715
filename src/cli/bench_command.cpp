// iesrgs bench: times the CPU hot paths on synthetic inputs. `raster`: the rasterizer forward,
// forward+backward and each stage, also of a trained model from a scene's cameras; `ssim`: the SSIM
// loss kernel with its backward, as a training step runs it; `adam`: the fused optimizer step over
// every Gaussian parameter.
#include <fmt/format.h>
#include <omp.h>
#include <torch/torch.h>

#include <algorithm>
#include <ctime>
#include <functional>
#include <vector>

#include "cli/commands.hpp"
#include "cli/validators.hpp"
#include "core/cpu_isa.hpp"
#include "core/math.hpp"
#include "core/memory.hpp"
#include "core/stopwatch.hpp"
#include "gs/benchmark_model.hpp"
#include "gs/model.hpp"
#include "gs/optimizer.hpp"
#include "io/model_file.hpp"
#include "io/scene.hpp"
#include "loss/benchmark_image.hpp"
#include "loss/ssim.hpp"
#include "raster/autograd.hpp"
#include "raster/cpu/dispatch.hpp"
#include "raster/rasterizer.hpp"
#include "raster/synthetic_scene.hpp"
#include "train/session.hpp"

namespace iesrgs::cli {

namespace {

struct RepeatArgs {
  int threads = 0;  // 0: OpenMP's default
  int iterations = 5;
};

struct RasterBenchArgs {
  int gaussians = 100000;
  int width = 800, height = 800;
  std::string model;  // a trained model to time instead of the synthetic scene
  std::string scene;  // whose training cameras see it
  int downscale = 1;
  double scale = 1;
  int views = 10;
  RepeatArgs repeat;
};

struct SsimBenchArgs {
  int width = 800, height = 800;
  RepeatArgs repeat{0, 20};
};

struct AdamBenchArgs {
  int gaussians = 500000;
  RepeatArgs repeat{0, 20};
};

struct Timing {
  double wall_ms = 0;  // median
  double cpu_ms = 0;   // mean, summed over threads
};

void set_bench_threads(const RepeatArgs& repeat) {
  // Through LibTorch, whose first operation on a thread would otherwise set OpenMP's thread
  // count back to its own.
  if (repeat.threads > 0) torch::set_num_threads(repeat.threads);
}

// Runs work(i) for i = -1 (a warm-up that sizes every buffer, not timed) up to iterations - 1.
// The median wall time, so that one disturbed run (a shared machine) does not skew the result;
// on a busy machine wall time overstates the cost, CPU time does not. CPU time is taken over all
// runs at once: Linux adds a thread's time running on another core to the process only at that
// core's scheduler tick, so the runs shorter than a tick would miss it one by one.
Timing time_runs(int iterations, const std::function<void(int)>& work) {
  std::vector<double> wall;
  std::clock_t cpu_start = 0;
  for (int it = -1; it < iterations; ++it) {
    if (it == 0) cpu_start = std::clock();
    const Stopwatch watch;
    work(it);
    if (it >= 0) wall.push_back(watch.milliseconds());
  }
  return {median(wall), 1000.0 * double(std::clock() - cpu_start) / CLOCKS_PER_SEC / iterations};
}

// Gaussians and the cameras the timed frames see them from, one frame per camera.
struct RasterWorkload {
  std::string description;
  raster::GaussianCloud synthetic;  // owns the arrays of a synthetic scene
  raster::GaussianTensors trained;  // owns those of a trained model
  raster::GaussianParams<float> params;
  std::vector<raster::RasterCamera<float>> cameras;
};

RasterWorkload synthetic_workload(const RasterBenchArgs& args) {
  RasterWorkload w;
  w.cameras = {raster::benchmark_camera(args.width, args.height)};
  w.synthetic = raster::synthetic_scene(args.gaussians, w.cameras[0], 1);
  w.params = w.synthetic.params();
  w.description =
      fmt::format("synthetic, {} Gaussians, {}x{}", args.gaussians, args.width, args.height);
  return w;
}

// A trained model seen from the first training cameras of a scene, as training renders it.
RasterWorkload trained_workload(const RasterBenchArgs& args) {
  const gs::GaussianModel model =
      gs::model_from_splat_cloud(read_model(train::trained_model_file(args.model)));
  SceneOptions options;
  options.downscale = args.downscale;
  const Scene scene = load_scene(args.scene, options);
  require_training_views(scene);
  RasterWorkload w;
  for (const Camera* camera : scene.split(Split::Train)) {
    if (int(w.cameras.size()) == args.views) break;
    w.cameras.push_back(raster::raster_camera<float>(camera->scaled(args.scale)));
  }
  w.trained = raster::render_tensors(model);
  w.params = raster::kernel_params(w.trained);
  w.description =
      fmt::format("{}, {} Gaussians, {} training views of {} at {}x{}", args.model, model.size(),
                  w.cameras.size(), args.scene, w.cameras[0].width, w.cameras[0].height);
  return w;
}

// This benchmark's image and gradient planes (ten floats a pixel) and the rasterizer's own two
// (final transmittance and contributor count): at a large --scale the frames, not the
// Gaussians, decide whether the run fits.
constexpr int64_t kRasterBenchBytesPerPixel = 12 * sizeof(float);

// Stage times of one frame, or their sum over the frames of one timed run.
struct RasterStageTimes {
  double forward = 0, project = 0, bin = 0, blend = 0, backward = 0;
  size_t entries = 0, drawn = 0;

  RasterStageTimes& operator+=(const RasterStageTimes& o) {
    forward += o.forward;
    project += o.project;
    bin += o.bin;
    blend += o.blend;
    backward += o.backward;
    entries += o.entries;
    drawn += o.drawn;
    return *this;
  }
};

// Renders g seen by cam into the buffers (sized for it or larger), then differentiates the render
// for the pixel gradients given.
RasterStageTimes time_raster_frame(const raster::GaussianParams<float>& g,
                                   const raster::RasterCamera<float>& cam,
                                   const raster::PixelGrads<float>& pixel_grads,
                                   raster::HostFrameBuffers& buffers,
                                   raster::RasterFrame<float>& frame) {
  using namespace raster;
  const float background[3] = {1, 1, 1};
  const Stopwatch watch;
  rasterize_forward(g, cam, background, frame, buffers.targets());
  const double forward_ms = watch.milliseconds();
  rasterize_backward(g, frame, pixel_grads, buffers.gaussian_grads());
  const RasterTimings& t = frame.timings;
  return RasterStageTimes{forward_ms,
                          t.project,
                          t.bin,
                          t.blend,
                          t.blend_backward + t.project_backward,
                          frame.bins.entry_count(),
                          size_t(std::count_if(buffers.radii.begin(), buffers.radii.end(),
                                               [](int r) { return r > 0; }))};
}

void run_raster_bench(const RasterBenchArgs& args) {
  set_bench_threads(args.repeat);
  using namespace raster;
  const RasterWorkload w = args.model.empty() ? synthetic_workload(args) : trained_workload(args);
  const RasterCamera<float>& largest =
      *std::max_element(w.cameras.begin(), w.cameras.end(), [](const auto& a, const auto& b) {
        return size_t(a.width) * a.height < size_t(b.width) * b.height;
      });
  const size_t plane = size_t(largest.width) * largest.height;
  require_memory(int64_t(plane) * kRasterBenchBytesPerPixel,
                 fmt::format("a {}x{} frame", largest.width, largest.height));
  HostFrameBuffers buffers(plane, size_t(w.params.count));
  // A loss gradient that reaches every output.
  const std::vector<float> dimage(3 * plane, 1e-3f), dalpha(plane, 1e-3f), ddepth(plane, 1e-4f);
  const PixelGrads<float> pixel_grads{dimage.data(), dalpha.data(), ddepth.data()};
  RasterFrame<float> frame;
  std::vector<RasterStageTimes> runs;
  const Timing total = time_runs(args.repeat.iterations, [&](int it) {
    RasterStageTimes sum;
    for (const RasterCamera<float>& cam : w.cameras)
      sum += time_raster_frame(w.params, cam, pixel_grads, buffers, frame);
    if (it >= 0) runs.push_back(sum);
  });
  const double frames = double(w.cameras.size());
  const auto per_frame = [&](double RasterStageTimes::*stage) {
    std::vector<double> v;
    for (const RasterStageTimes& r : runs) v.push_back(r.*stage / frames);
    return median(v);
  };
  fmt::print("scene: {}\n", w.description);
  fmt::print(
      "per frame: {:.0f} Gaussians drawn, {:.0f} tile entries; {} threads, {} iterations "
      "(medians)\n",
      double(runs[0].drawn) / frames, double(runs[0].entries) / frames, omp_get_max_threads(),
      args.repeat.iterations);
  fmt::print("blend kernels: {}\n", cpu::describe_isa(cpu_isa::active()));
  fmt::print("forward: {:.1f} ms\n", per_frame(&RasterStageTimes::forward));
  fmt::print("forward+backward: {:.1f} ms\n", total.wall_ms / frames);
  fmt::print("  projection: {:.1f} ms\n", per_frame(&RasterStageTimes::project));
  fmt::print("  binning/sort: {:.1f} ms\n", per_frame(&RasterStageTimes::bin));
  fmt::print("  blend: {:.1f} ms\n", per_frame(&RasterStageTimes::blend));
  fmt::print("  backward: {:.1f} ms\n", per_frame(&RasterStageTimes::backward));
  fmt::print("cpu time, forward+backward: {:.1f} ms over all threads (mean)\n",
             total.cpu_ms / frames);
}

void run_ssim_bench(const SsimBenchArgs& args) {
  set_bench_threads(args.repeat);
  const loss::ImageShape shape{args.height, args.width, 3};
  const std::vector<float> x = loss::benchmark_image(shape, 1), y = loss::benchmark_image(shape, 2);
  std::vector<float> partials(loss::ssim_partials_size(shape)), grad(shape.values());
  const std::vector<float> weight(shape.pixels(), 1.f / float(shape.pixels()));
  const Timing forward = time_runs(args.repeat.iterations, [&](int) {
    loss::ssim<float>(x.data(), y.data(), shape, nullptr, partials.data());
  });
  // What a training step pays: the forward with partials, then the backward of the mean.
  const Timing total = time_runs(args.repeat.iterations, [&](int) {
    loss::ssim<float>(x.data(), y.data(), shape, nullptr, partials.data());
    loss::ssim_backward<float>(x.data(), y.data(), shape, partials.data(), weight.data(),
                               grad.data());
  });
  fmt::print("image: {}x{} RGB, {} threads, {} iterations (medians)\n", args.width, args.height,
             omp_get_max_threads(), args.repeat.iterations);
  fmt::print("row loops: {}\n", cpu_isa::name(cpu_isa::active()));
  fmt::print("forward (with partials): {:.2f} ms\n", forward.wall_ms);
  fmt::print("forward+backward: {:.2f} ms ({:.1f} Mpixel/s)\n", total.wall_ms,
             double(shape.pixels()) / total.wall_ms / 1e3);
  fmt::print("cpu time, forward+backward: {:.2f} ms over all threads (mean)\n", total.cpu_ms);
}

void run_adam_bench(const AdamBenchArgs& args) {
  set_bench_threads(args.repeat);
  const int64_t n = args.gaussians;
  gs::GaussianModel model = gs::benchmark_model(n);
  int64_t floats = 0;
  for (int p = 0; p < gs::kParamCount; ++p) floats += model.param(gs::Param(p)).numel();
  gs::GaussianOptimizer optimizer(model, gs::LearningRates{}, 4.0);
  const Timing step = time_runs(args.repeat.iterations, [&](int) { optimizer.step(model); });
  // Each float: parameter, gradient and both moments read, parameter and moments written.
  const double bytes = double(floats) * sizeof(float) * 7;
  fmt::print("model: {} Gaussians ({} floats), {} threads, {} iterations (medians)\n", n, floats,
             omp_get_max_threads(), args.repeat.iterations);
  fmt::print("Adam step: {:.2f} ms ({:.1f} GB/s of parameters, gradients and moments)\n",
             step.wall_ms, bytes / step.wall_ms / 1e6);
  fmt::print("cpu time: {:.2f} ms over all threads (mean)\n", step.cpu_ms);
}

void add_repeat_options(CLI::App* command, RepeatArgs& repeat) {
  // More threads than any machine has cores only makes OpenMP spawn and wait for them.
  command->add_option("--threads", repeat.threads, "OpenMP threads (0, the default: all cores)")
      ->check(kNonNegative)
      ->check(CLI::Range(0, 1024));
  command->add_option("--iterations", repeat.iterations, "Timed iterations")
      ->capture_default_str()
      ->check(kPositive);
}

void add_image_size(CLI::App* command, int& width, int& height) {
  command->add_option("--width", width, "Image width")->capture_default_str()->check(kPositive);
  command->add_option("--height", height, "Image height")->capture_default_str()->check(kPositive);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto* bench = app.add_subcommand(
      "bench", "Time parts of the system on synthetic inputs or a trained model");
  bench->require_subcommand(1);

  auto* raster = bench->add_subcommand("raster", "Time the CPU rasterizer, forward and backward");
  auto raster_args = std::make_shared<RasterBenchArgs>();
  raster->add_option("--gaussians", raster_args->gaussians, "Number of Gaussians")
      ->capture_default_str()
      ->check(kNonNegative);
  add_image_size(raster, raster_args->width, raster_args->height);
  auto* model = raster->add_option("--model", raster_args->model,
                                   "Time this trained model (output folder, .ply, .spz or .splat) "
                                   "instead of a synthetic scene");
  raster
      ->add_option("--scene", raster_args->scene,
                   "The scene whose first training cameras see --model, one frame each")
      ->needs(model);
  model->needs("--scene");
  raster->add_option("--downscale", raster_args->downscale, "Cameras at 1/k of the scene's size")
      ->capture_default_str()
      ->check(kPositive);
  raster
      ->add_option("--scale", raster_args->scale,
                   "Resolution factor over the cameras' (SR-splatting renders at 4)")
      ->capture_default_str()
      ->check(kPositive);
  raster->add_option("--views", raster_args->views, "Training cameras to render")
      ->capture_default_str()
      ->check(kPositive);
  add_repeat_options(raster, raster_args->repeat);
  raster->callback([raster_args] { run_raster_bench(*raster_args); });

  auto* ssim = bench->add_subcommand("ssim", "Time the SSIM loss kernel, forward and backward");
  auto ssim_args = std::make_shared<SsimBenchArgs>();
  add_image_size(ssim, ssim_args->width, ssim_args->height);
  add_repeat_options(ssim, ssim_args->repeat);
  ssim->callback([ssim_args] { run_ssim_bench(*ssim_args); });

  auto* adam = bench->add_subcommand("adam", "Time the optimizer step over every parameter");
  auto adam_args = std::make_shared<AdamBenchArgs>();
  adam->add_option("--gaussians", adam_args->gaussians, "Number of Gaussians")
      ->capture_default_str()
      ->check(kPositive);
  add_repeat_options(adam, adam_args->repeat);
  adam->callback([adam_args] { run_adam_bench(*adam_args); });
}

}  // namespace iesrgs::cli
