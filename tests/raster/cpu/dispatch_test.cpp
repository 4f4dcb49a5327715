// The instruction-set variants of the CPU projection and blend passes agree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "raster/cpu/dispatch.hpp"
#include "raster/raster_test_scene.hpp"
#include "support/active_isa.hpp"

namespace iesrgs::raster::testkit {
namespace {

using cpu::Isa;
using testing::ActiveIsa;

// A render and every gradient of a fixed random linear loss of it.
template <typename T>
struct Differentiated {
  KernelRender<T> render;
  std::vector<std::vector<T>> grads;  // means, log-scales, quats, logits, SH, viewspace (+ abs)
};

template <typename T>
std::vector<T> random_values(size_t count, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<T> v(count);
  for (T& x : v) x = T(u(rng));
  return v;
}

template <typename T>
Differentiated<T> render_and_differentiate(Isa isa, const Scene<T>& s, const Camera& cam) {
  const ActiveIsa active(isa);
  const T background[3] = {T(0.2), T(0.5), T(0.9)};
  Differentiated<T> d{kernel_render(s, cam, background), {}};
  std::mt19937 rng(5);
  const std::vector<T> dimage = random_values<T>(d.render.image.size(), rng);
  const std::vector<T> dalpha = random_values<T>(d.render.alpha.size(), rng);
  const std::vector<T> ddepth = random_values<T>(d.render.depth.size(), rng);
  const size_t n = s.count();
  for (size_t size : {3 * n, 3 * n, 4 * n, n, 3 * n, 45 * n, 2 * n, 2 * n})
    d.grads.emplace_back(size);
  std::vector<T*> g;
  for (std::vector<T>& v : d.grads) g.push_back(v.data());
  rasterize_backward(s.params(), d.render.frame,
                     PixelGrads<T>{dimage.data(), dalpha.data(), ddepth.data()},
                     GaussianGrads<T>{g[0], g[1], g[2], g[3], g[4], g[5], g[6], g[7]});
  return d;
}

// Largest difference relative to the largest magnitude of the group: single gradients of nearly
// cancelling terms have no meaningful relative error of their own.
template <typename T>
double relative_diff(const std::vector<T>& a, const std::vector<T>& b) {
  double scale = 0;
  for (T x : b) scale = std::max(scale, std::abs(double(x)));
  EXPECT_GT(scale, 0) << "the comparison would pass vacuously";
  return max_abs_diff(a, b) / scale;
}

template <typename T>
void expect_variants_agree(const Camera& cam, unsigned seed) {
  SCOPED_TRACE(::testing::Message() << "seed " << seed << ", " << sizeof(T) << "-byte floats");
  const Scene<T> scene = random_scene(cam, 200, 3, seed).template cast<T>();
  const Differentiated<T> base = render_and_differentiate(Isa::kBaseline, scene, cam);
  const Differentiated<T> avx2 = render_and_differentiate(Isa::kAvx2, scene, cam);
  EXPECT_EQ(avx2.render.radii, base.render.radii);
  EXPECT_LT(max_abs_diff(avx2.render.image, base.render.image), 1e-5);
  EXPECT_LT(max_abs_diff(avx2.render.alpha, base.render.alpha), 1e-5);
  EXPECT_LT(max_abs_diff(avx2.render.depth, base.render.depth), 1e-5);
  // The variants round differently (fused multiply-adds): in float, the gradients of the needle
  // and image-covering Gaussians cancel over many pixels and keep about four digits.
  const double tolerance = sizeof(T) == sizeof(float) ? 2e-4 : 1e-10;
  for (size_t k = 0; k < base.grads.size(); ++k)
    EXPECT_LT(relative_diff(avx2.grads[k], base.grads[k]), tolerance) << "gradient group " << k;
}

TEST(RasterCpuIsa, Avx2AgreesWithBaselineOnRandomScenes) {
  if (!cpu_isa::supported(Isa::kAvx2))
    GTEST_SKIP() << "no AVX2 variant: not built (native, Debug or non-x86 build) or no CPU support";
  EXPECT_EQ(cpu::describe_isa(Isa::kAvx2), "avx2 (32-byte packs)");
  // Odd sizes exercise partial packs and border tiles.
  const Camera cameras[] = {test_camera(64, 48), posed_test_camera(70, 53),
                            posed_test_camera(33, 47), test_camera(96, 80)};
  unsigned seed = 1;
  for (const Camera& cam : cameras) {
    expect_variants_agree<float>(cam, seed);
    expect_variants_agree<double>(cam, seed++);
  }
}

TEST(RasterCpuIsa, BaselineIsDescribedWithItsPackWidth) {
  EXPECT_EQ(cpu::describe_isa(Isa::kBaseline).rfind("baseline (", 0), 0u);
}

}  // namespace
}  // namespace iesrgs::raster::testkit
