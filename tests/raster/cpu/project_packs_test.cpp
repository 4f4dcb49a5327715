// The CPU projection passes, which run packs of Gaussians in SIMD lanes, give the scalar formulas'
// results (raster/project.hpp, one Gaussian at a time) to the bit, in every instruction-set
// variant. This file compiles without fused multiply-adds, as the passes do (CMakeLists.txt).
#include <gtest/gtest.h>

#include <cstring>

#include "raster/cpu/dispatch.hpp"
#include "raster/cpu/kernels.hpp"
#include "raster/project.hpp"
#include "raster/raster_test_scene.hpp"
#include "support/active_isa.hpp"
#include "support/compare.hpp"

namespace iesrgs::raster::testkit {
namespace {

using cpu::Isa;

struct Projected {
  std::vector<Splat<float>> splats;
  std::vector<PixelRect> rects;
  std::vector<int32_t> radii;
};

// The reference: the scalar formulas, one Gaussian at a time.
Projected project_each(const GaussianParams<float>& g, const RasterCamera<float>& cam) {
  Projected out{std::vector<Splat<float>>(g.count), std::vector<PixelRect>(g.count),
                std::vector<int32_t>(g.count)};
  for (int i = 0; i < g.count; ++i) {
    Projection<float> p;
    if (!project(g, i, cam, p)) continue;
    out.splats[i] = make_splat(g, i, cam, p);
    splat_rect(out.splats[i], p.filtered, cam.width, cam.height, out.rects[i], out.radii[i]);
  }
  return out;
}

Projected project_passes(Isa isa, const GaussianParams<float>& g, const RasterCamera<float>& cam) {
  Projected out{std::vector<Splat<float>>(g.count), std::vector<PixelRect>(g.count),
                std::vector<int32_t>(g.count, -1)};
  const testing::ActiveIsa active(isa);
  cpu::project_forward(g, cam, out.splats.data(), out.rects.data(), out.radii.data());
  return out;
}

// Gradient arrays in GaussianGrads order: means, log-scales, quats, logits, SH (DC, rest),
// viewspace (+ abs).
using Grads = std::vector<std::vector<float>>;

GaussianGrads<float> view(Grads& d) {
  return {d[0].data(), d[1].data(), d[2].data(), d[3].data(),
          d[4].data(), d[5].data(), d[6].data(), d[7].data()};
}

Grads zero_grads(int n) {
  Grads d;
  for (int size : {3 * n, 3 * n, 4 * n, n, 3 * n, 45 * n, 2 * n, 2 * n})
    d.emplace_back(size_t(size));
  return d;
}

// Random splat gradients, every third Gaussian's all zero (skipped by the passes).
std::vector<SplatGrad<float>> random_splat_grads(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<SplatGrad<float>> grads(size_t(n), SplatGrad<float>{});
  for (int i = 0; i < n; ++i) {
    if (i % 3 == 0) continue;
    SplatGrad<float>& d = grads[size_t(i)];
    for (float* f : {&d.x, &d.y, &d.conic_xx, &d.conic_xy, &d.conic_yy, &d.opacity, &d.color[0],
                     &d.color[1], &d.color[2], &d.depth, &d.abs_x, &d.abs_y})
      *f = u(rng);
  }
  return grads;
}

bool same_bits(const Splat<float>& a, const Splat<float>& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

void expect_passes_match_scalar(const Scene<float>& scene, const Camera& camera, unsigned seed) {
  const GaussianParams<float> g = scene.params();
  const RasterCamera<float> cam = raster_camera<float>(camera);
  const Projected reference = project_each(g, cam);
  const std::vector<SplatGrad<float>> splat_grads = random_splat_grads(g.count, seed);
  Grads reference_grads = zero_grads(g.count);
  for (int i = 0; i < g.count; ++i)
    if (!splat_grads[i].is_zero())
      project_backward(g, i, cam, splat_grads[i], view(reference_grads));

  int visible = 0;
  for (Isa isa : {Isa::kBaseline, Isa::kAvx2}) {
    if (!cpu_isa::supported(isa)) continue;
    SCOPED_TRACE(cpu::describe_isa(isa));
    const Projected lanes = project_passes(isa, g, cam);
    EXPECT_EQ(lanes.radii, reference.radii);
    for (int i = 0; i < g.count; ++i) {
      const PixelRect &a = lanes.rects[i], &b = reference.rects[i];
      EXPECT_TRUE(a.x0 == b.x0 && a.y0 == b.y0 && a.x1 == b.x1 && a.y1 == b.y1) << "Gaussian " << i;
      if (reference.radii[i] > 0) {
        ++visible;
        EXPECT_TRUE(same_bits(lanes.splats[i], reference.splats[i])) << "Gaussian " << i;
      }
    }
    Grads grads = zero_grads(g.count);
    {
      const testing::ActiveIsa active(isa);
      cpu::project_backward(g, cam, splat_grads.data(), view(grads));
    }
    for (size_t k = 0; k < grads.size(); ++k)
      EXPECT_TRUE(testing::same_bits(grads[k], reference_grads[k])) << "gradient group " << k;
  }
  EXPECT_GT(visible, g.count / 2) << "too few Gaussians on screen to compare";
}

// Odd counts leave a partial last pack; the cameras put Gaussians behind the near plane, beyond
// the Jacobian clamp and under the mip filter's determinant floor.
TEST(ProjectLanes, MatchTheScalarFormulasToTheBit) {
  unsigned seed = 1;
  for (const Camera& cam : {test_camera(64, 48), posed_test_camera(70, 53)})
    for (int degree : {0, 1, 3}) {
      SCOPED_TRACE(::testing::Message() << "SH degree " << degree << ", seed " << seed);
      expect_passes_match_scalar(random_scene(cam, 203, degree, seed).cast<float>(), cam, seed);
      ++seed;
    }
}

TEST(ProjectLanes, MatchWithoutTheMipFilters) {
  const Camera cam = posed_test_camera(70, 53);
  Scene<float> scene = random_scene(cam, 101, 3, 9).cast<float>();
  scene.filter_std.clear();
  scene.antialiased = false;
  expect_passes_match_scalar(scene, cam, 9);
}

}  // namespace
}  // namespace iesrgs::raster::testkit
