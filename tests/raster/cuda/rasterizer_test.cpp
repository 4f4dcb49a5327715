// The CUDA rasterizer against the CPU one on random scenes: images, radii and every gradient.
// Skipped where no CUDA device can be used.
#include "raster/cuda/rasterizer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/cuda/device.hpp"
#include "core/cuda/device_array.hpp"
#include "core/error.hpp"
#include "gs/sh.hpp"
#include "raster/synthetic_scene.hpp"
#include "support/compare.hpp"

namespace iesrgs::raster::cuda {
namespace {

using iesrgs::cuda::DeviceArray;

class CudaRasterizer : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!iesrgs::cuda::device_available()) GTEST_SKIP() << "no CUDA device";
  }
};

// The scene of synthetic_scene seen from a camera that is rotated and moved: the means are mapped
// back to world space, so the view is the same but every pose term takes part.
RasterCamera<float> posed(RasterCamera<float> cam, GaussianCloud& cloud) {
  const float c = std::cos(0.3f), s = std::sin(0.3f);
  const float r[9] = {c, 0, s, 0, 1, 0, -s, 0, c};  // world-to-camera
  const float t[3] = {0.2f, -0.1f, 0.5f};
  std::copy_n(r, 9, cam.rotation);
  std::copy_n(t, 3, cam.translation);
  for (size_t i = 0; i < cloud.means.size(); i += 3) {
    const float p[3] = {cloud.means[i] - t[0], cloud.means[i + 1] - t[1],
                        cloud.means[i + 2] - t[2]};
    for (int k = 0; k < 3; ++k)
      cloud.means[i + k] = r[k] * p[0] + r[3 + k] * p[1] + r[6 + k] * p[2];  // R^T p
  }
  return cam;
}

struct Frame {
  std::vector<float> image, alpha, depth;
  std::vector<int32_t> radii;
};

struct Grads {
  std::vector<float> means, log_scales, quats, opacity_logits, sh_dc, sh_rest, viewspace,
      viewspace_abs;
};

struct PixelGradsHost {
  std::vector<float> image, alpha, depth;
};

PixelGradsHost random_pixel_grads(int width, int height, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1e-2f, 1e-2f);
  const size_t plane = size_t(width) * height;
  PixelGradsHost p{std::vector<float>(3 * plane), std::vector<float>(plane),
                   std::vector<float>(plane)};
  for (auto* v : {&p.image, &p.alpha, &p.depth})
    for (float& x : *v) x = u(rng);
  return p;
}

Grads sized_grads(size_t n) {
  return {std::vector<float>(3 * n), std::vector<float>(3 * n),
          std::vector<float>(4 * n), std::vector<float>(n),
          std::vector<float>(3 * n), std::vector<float>(gs::kShRestFloats * n),
          std::vector<float>(2 * n), std::vector<float>(2 * n)};
}

void render_cpu(const GaussianCloud& cloud, const RasterCamera<float>& cam, const float bg[3],
                const PixelGradsHost& dpix, Frame& f, Grads& g) {
  const size_t plane = size_t(cam.width) * cam.height, n = size_t(cloud.count());
  f = {std::vector<float>(3 * plane), std::vector<float>(plane), std::vector<float>(plane),
       std::vector<int32_t>(n)};
  g = sized_grads(n);
  RasterFrame<float> frame;
  rasterize_forward(
      cloud.params(), cam, bg, frame,
      RenderTargets<float>{f.image.data(), f.alpha.data(), f.depth.data(), f.radii.data()});
  rasterize_backward(cloud.params(), frame,
                     PixelGrads<float>{dpix.image.data(), dpix.alpha.data(), dpix.depth.data()},
                     GaussianGrads<float>{g.means.data(), g.log_scales.data(), g.quats.data(),
                                          g.opacity_logits.data(), g.sh_dc.data(), g.sh_rest.data(),
                                          g.viewspace.data(), g.viewspace_abs.data()});
}

void render_cuda(Rasterizer& rasterizer, const GaussianCloud& cloud, const RasterCamera<float>& cam,
                 const float bg[3], const PixelGradsHost& dpix, Frame& f, Grads& g) {
  const size_t plane = size_t(cam.width) * cam.height, n = size_t(cloud.count());
  const DeviceGaussians scene(cloud);
  DeviceArray<float> image, alpha, depth;
  DeviceArray<int32_t> radii;
  rasterizer.forward(scene.params(), cam, bg,
                     RenderTargets<float>{image.reserve(3 * plane), alpha.reserve(plane),
                                          depth.reserve(plane), radii.reserve(n)});
  const DeviceArray<float> dimage(dpix.image), dalpha(dpix.alpha), ddepth(dpix.depth);
  const Grads sizes = sized_grads(n);
  DeviceArray<float> means(sizes.means), scales(sizes.log_scales), quats(sizes.quats),
      logits(sizes.opacity_logits), sh_dc(sizes.sh_dc), sh_rest(sizes.sh_rest), vs(sizes.viewspace),
      vs_abs(sizes.viewspace_abs);
  rasterizer.backward(scene.params(),
                      PixelGrads<float>{dimage.data(), dalpha.data(), ddepth.data()},
                      GaussianGrads<float>{means.data(), scales.data(), quats.data(), logits.data(),
                                           sh_dc.data(), sh_rest.data(), vs.data(), vs_abs.data()});
  rasterizer.synchronize();
  f = {image.download(), alpha.download(), depth.download(), radii.download()};
  g = {means.download(), scales.download(),  quats.download(), logits.download(),
       sh_dc.download(), sh_rest.download(), vs.download(),    vs_abs.download()};
}

// Where a splat's alpha lies within rounding of the 1/255 cut-off, or a pixel's transmittance
// within rounding of the 1e-4 stop, the CPU and the GPU may decide differently (their exp and
// fused multiply-adds differ in the last bits), and the pixel differs by that one splat's
// contribution. Such pixels are rare; every other one must agree within `tolerance`.
void expect_close_pixels(const std::vector<float>& gpu, const std::vector<float>& cpu,
                         float tolerance, const char* name) {
  ASSERT_EQ(gpu.size(), cpu.size());
  size_t off = 0;
  float worst = 0;
  for (size_t i = 0; i < gpu.size(); ++i) {
    const float d = std::abs(gpu[i] - cpu[i]);
    worst = std::max(worst, d);
    off += d > tolerance;
  }
  EXPECT_LE(off, std::max<size_t>(2, gpu.size() / 10000))
      << name << ": " << off << " of " << gpu.size() << " values off by more than " << tolerance
      << ", worst " << worst;
  std::printf("%s: %zu of %zu values off by more than %g, worst %g\n", name, off, gpu.size(),
              double(tolerance), double(worst));
}

void expect_same(const GaussianCloud& cloud, const RasterCamera<float>& cam, const float bg[3],
                 Rasterizer& rasterizer) {
  const PixelGradsHost dpix = random_pixel_grads(cam.width, cam.height, 7);
  Frame cpu, gpu;
  Grads dcpu, dgpu;
  render_cpu(cloud, cam, bg, dpix, cpu, dcpu);
  render_cuda(rasterizer, cloud, cam, bg, dpix, gpu, dgpu);

  expect_close_pixels(gpu.image, cpu.image, 1e-4f, "image");
  expect_close_pixels(gpu.alpha, cpu.alpha, 1e-4f, "alpha");
  const float depth_scale = *std::max_element(cpu.depth.begin(), cpu.depth.end());
  expect_close_pixels(gpu.depth, cpu.depth, 1e-4f * std::max(depth_scale, 1.f), "depth");
  EXPECT_EQ(gpu.radii, cpu.radii);

  const struct {
    const char* name;
    const std::vector<float>&a, &b;
  } arrays[] = {{"means", dgpu.means, dcpu.means},
                {"log_scales", dgpu.log_scales, dcpu.log_scales},
                {"quats", dgpu.quats, dcpu.quats},
                {"opacity_logits", dgpu.opacity_logits, dcpu.opacity_logits},
                {"sh_dc", dgpu.sh_dc, dcpu.sh_dc},
                {"sh_rest", dgpu.sh_rest, dcpu.sh_rest},
                {"viewspace", dgpu.viewspace, dcpu.viewspace},
                {"viewspace_abs", dgpu.viewspace_abs, dcpu.viewspace_abs}};
  for (const auto& arr : arrays) {
    const double error = testing::relative_l2_error(arr.a, arr.b);
    EXPECT_LE(error, 1e-3) << arr.name;
    std::printf("d%s: relative error %.3g\n", arr.name, error);
  }
}

TEST_F(CudaRasterizer, MatchesCpuOnARandomSceneWithBorderTiles) {
  const RasterCamera<float> cam = benchmark_camera(250, 190);
  const GaussianCloud cloud = synthetic_scene(20000, cam, 3);
  const float white[3] = {1, 1, 1};
  Rasterizer rasterizer;
  expect_same(cloud, cam, white, rasterizer);
  EXPECT_GT(rasterizer.entry_count(), 20000u);
}

TEST_F(CudaRasterizer, MatchesCpuFromAPosedCameraWithoutMipFilters) {
  GaussianCloud cloud = synthetic_scene(8000, benchmark_camera(320, 240), 5);
  const RasterCamera<float> cam = posed(benchmark_camera(320, 240), cloud);
  cloud.sh_degree = 1;
  cloud.antialiased = false;
  cloud.filter_std.clear();  // no 3D filter
  const float black[3] = {0, 0, 0};
  Rasterizer rasterizer;
  expect_same(cloud, cam, black, rasterizer);
}

// Many opaque splats: most pixels stop early, the cut-off paths of both passes run.
TEST_F(CudaRasterizer, MatchesCpuWhereOpaqueSplatsStopThePixels) {
  const RasterCamera<float> cam = benchmark_camera(96, 80);
  GaussianCloud cloud = synthetic_scene(30000, cam, 9);
  for (float& logit : cloud.opacity_logits) logit = std::abs(logit) + 2.f;
  const float grey[3] = {0.5f, 0.5f, 0.5f};
  Rasterizer rasterizer;
  expect_same(cloud, cam, grey, rasterizer);
}

// One rasterizer through scenes that grow, shrink and vanish: its buffers are reused.
TEST_F(CudaRasterizer, ReusesItsBuffersAcrossScenesOfAnySize) {
  Rasterizer rasterizer;
  const float bg[3] = {0.2f, 0.4f, 0.6f};
  for (const int count : {500, 40000, 3000, 0}) {
    SCOPED_TRACE(count);
    const RasterCamera<float> cam = benchmark_camera(128 + count % 7, 96);
    expect_same(synthetic_scene(count, cam, uint32_t(count)), cam, bg, rasterizer);
  }
  // Every Gaussian behind the camera: nothing is binned, the image is the background.
  const RasterCamera<float> cam = benchmark_camera(64, 64);
  GaussianCloud behind = synthetic_scene(1000, cam, 2);
  for (size_t i = 2; i < behind.means.size(); i += 3) behind.means[i] = -behind.means[i];
  expect_same(behind, cam, bg, rasterizer);
  EXPECT_EQ(rasterizer.entry_count(), 0u);
}

TEST_F(CudaRasterizer, RejectsABackwardPassForAnotherScene) {
  const RasterCamera<float> cam = benchmark_camera(64, 48);
  const DeviceGaussians scene(synthetic_scene(100, cam, 1));
  const DeviceGaussians other(synthetic_scene(101, cam, 1));
  DeviceArray<float> image, alpha, depth;
  DeviceArray<int32_t> radii;
  Rasterizer rasterizer;
  const float bg[3] = {0, 0, 0};
  EXPECT_THROW(rasterizer.forward(scene.params(), cam, bg,
                                  RenderTargets<float>{image.reserve(3 * 64 * 48), nullptr,
                                                       depth.reserve(64 * 48), radii.reserve(100)}),
               Error);
  rasterizer.forward(scene.params(), cam, bg,
                     RenderTargets<float>{image.reserve(3 * 64 * 48), alpha.reserve(64 * 48),
                                          depth.reserve(64 * 48), radii.reserve(100)});
  DeviceArray<float> grads;
  float* d = grads.reserve(48 * 101);
  EXPECT_THROW(rasterizer.backward(other.params(), PixelGrads<float>{},
                                   GaussianGrads<float>{d, d, d, d, d, d, nullptr, nullptr}),
               Error);
}

}  // namespace
}  // namespace iesrgs::raster::cuda
