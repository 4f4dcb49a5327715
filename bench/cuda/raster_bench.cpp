// Frame times of the CUDA rasterizer on the synthetic scene of the CPU benchmarks: forward, and
// forward + backward, per scene size, with the stages of each; `--cpu` times the CPU rasterizer on
// the same scenes too. Then the CUDA SSIM at the same image size.
//   iesrgs_cuda_bench [--size WxH] [--gaussians N,N,...] [--frames F] [--cpu]
#include <fmt/format.h>
#include <omp.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/cuda/device.hpp"
#include "core/cuda/device_array.hpp"
#include "core/error.hpp"
#include "core/stopwatch.hpp"
#include "loss/cuda/ssim.hpp"
#include "loss/ssim.hpp"
#include "raster/cuda/rasterizer.hpp"
#include "raster/rasterizer.hpp"
#include "raster/synthetic_scene.hpp"

namespace iesrgs::raster {
namespace {

using iesrgs::cuda::check;

struct Options {
  int width = 800, height = 800, frames = 50;
  std::vector<int> gaussians = {100000, 500000, 1000000};
  bool cpu = false;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) fail("{}: missing value", arg);
      return argv[++i];
    };
    if (arg == "--size") {
      if (std::sscanf(value().c_str(), "%dx%d", &o.width, &o.height) != 2)
        fail("--size: expected WxH");
    } else if (arg == "--gaussians") {
      o.gaussians.clear();
      const std::string list = value();
      for (size_t p = 0; p < list.size();) {
        const size_t comma = std::min(list.find(',', p), list.size());
        o.gaussians.push_back(std::atoi(list.substr(p, comma - p).c_str()));
        p = comma + 1;
      }
    } else if (arg == "--frames") {
      o.frames = std::atoi(value().c_str());
    } else if (arg == "--cpu") {
      o.cpu = true;
    } else {
      fail("unknown option {}", arg);
    }
  }
  return o;
}

// Every buffer of one frame, forward and backward, on the device.
struct CudaFrame {
  cuda::DeviceGaussians scene;
  iesrgs::cuda::DeviceArray<float> image, alpha, depth, dimage, grads;
  iesrgs::cuda::DeviceArray<int32_t> radii;
  cuda::Rasterizer rasterizer;

  CudaFrame(const GaussianCloud& cloud, size_t pixels) : scene(cloud) {
    image.reserve(3 * pixels);
    alpha.reserve(pixels);
    depth.reserve(pixels);
    dimage.upload(std::vector<float>(3 * pixels, 1e-3f));
    radii.reserve(size_t(cloud.count()));
    grads.reserve(packed_grads_size(size_t(cloud.count())));
  }
  void forward(const RasterCamera<float>& cam) {
    const float background[3] = {1, 1, 1};
    rasterizer.forward(
        scene.params(), cam, background,
        RenderTargets<float>{image.data(), alpha.data(), depth.data(), radii.data()});
  }
  void backward() {
    rasterizer.backward(scene.params(), PixelGrads<float>{dimage.data(), nullptr, nullptr},
                        packed_grads(grads.data(), scene.opacity_logits.size()));
  }
};

// Mean milliseconds per call of f over `frames` calls after two warm-up calls.
template <typename F>
double time_frames(int frames, F&& f) {
  for (int i = 0; i < 2; ++i) f();
  const Stopwatch watch;
  for (int i = 0; i < frames; ++i) f();
  return watch.milliseconds() / frames;
}

void bench_cpu(const GaussianCloud& cloud, const RasterCamera<float>& cam, int frames) {
  const size_t pixels = size_t(cam.width) * cam.height, n = size_t(cloud.count());
  HostFrameBuffers buffers(pixels, n);
  const std::vector<float> dimage(3 * pixels, 1e-3f);
  RasterFrame<float> frame;
  const float background[3] = {1, 1, 1};
  const auto forward = [&] {
    rasterize_forward(cloud.params(), cam, background, frame, buffers.targets());
  };
  const double fwd = time_frames(frames, forward);
  const double both = time_frames(frames, [&] {
    forward();
    rasterize_backward(cloud.params(), frame, PixelGrads<float>{dimage.data(), nullptr, nullptr},
                       buffers.gaussian_grads());
  });
  fmt::print("| {:>9} | CPU, {:>2} threads | {:>9.3f} | {:>9.3f} | {:>7.1f} | | | |\n", n,
             omp_get_max_threads(), fwd, both, 1000.0 / fwd);
}

// The training loss's SSIM on a rendered-size image: forward with partials, then the backward.
void bench_ssim(int width, int height, int frames) {
  const loss::ImageShape shape{width, height, 3};
  iesrgs::cuda::DeviceArray<float> x(std::vector<float>(shape.values(), 0.4f));
  iesrgs::cuda::DeviceArray<float> y(std::vector<float>(shape.values(), 0.6f));
  iesrgs::cuda::DeviceArray<float> weight(std::vector<float>(shape.pixels(), 1.f));
  iesrgs::cuda::DeviceArray<float> partials, grad, mean;
  partials.reserve(loss::ssim_partials_size(shape));
  grad.reserve(shape.values());
  mean.reserve(1);
  loss::cuda::Ssim ssim;
  const double ms = time_frames(frames, [&] {
    ssim.forward(x.data(), y.data(), shape, nullptr, partials.data(), mean.data());
    ssim.backward(x.data(), y.data(), shape, partials.data(), weight.data(), grad.data());
    check(cudaDeviceSynchronize(), "ssim");
  });
  fmt::print("\nSSIM {}x{}x3, forward with partials + backward: {:.3f} ms\n", width, height, ms);
}

int run(int argc, char** argv) {
  const Options o = parse(argc, argv);
  if (!iesrgs::cuda::device_available()) fail("no CUDA device can be used");
  const RasterCamera<float> cam = benchmark_camera(o.width, o.height);
  fmt::print("{} at {}x{}, {} frames after 2 warm-up frames, white background\n",
             iesrgs::cuda::device_description(), o.width, o.height, o.frames);
  fmt::print(
      "| Gaussians | device | forward ms | fwd+bwd ms | FPS | entries | project / bin / "
      "blend ms | blend bwd / project bwd ms |\n|---|---|---|---|---|---|---|---|\n");
  for (const int count : o.gaussians) {
    const GaussianCloud cloud = synthetic_scene(count, cam, 1);
    CudaFrame f(cloud, size_t(o.width) * o.height);
    const double fwd = time_frames(o.frames, [&] {
      f.forward(cam);
      f.rasterizer.synchronize();
    });
    const double both = time_frames(o.frames, [&] {
      f.forward(cam);
      f.backward();
      f.rasterizer.synchronize();
    });
    const RasterTimings t = f.rasterizer.timings();
    fmt::print(
        "| {:>9} | CUDA | {:>9.3f} | {:>9.3f} | {:>7.1f} | {} | {:.3f} / {:.3f} / {:.3f} | "
        "{:.3f} / {:.3f} |\n",
        count, fwd, both, 1000.0 / fwd, f.rasterizer.entry_count(), t.project, t.bin, t.blend,
        t.blend_backward, t.project_backward);
    if (o.cpu) bench_cpu(cloud, cam, std::max(1, o.frames / 10));
  }
  bench_ssim(o.width, o.height, o.frames);
  return 0;
}

}  // namespace
}  // namespace iesrgs::raster

int main(int argc, char** argv) {
  try {
    return iesrgs::raster::run(argc, argv);
  } catch (const std::exception& e) {
    fmt::print(stderr, "iesrgs_cuda_bench: {}\n", e.what());
    return 1;
  }
}
