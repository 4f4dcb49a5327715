#include <gtest/gtest.h>
#include <omp.h>

#include <limits>
#include <tuple>
#include <utility>

#include "core/error.hpp"
#include "raster_test_scene.hpp"
#include "reference_renderer.hpp"

namespace iesrgs::raster::testkit {
namespace {

const double kRasterBackground[3] = {0.2, 0.5, 0.9};

struct ReferenceCase {
  Camera camera;
  int degree;
  unsigned seed;
  bool antialiased = true;
};

void expect_matches_reference(const ReferenceCase& c, double tolerance_float,
                              double tolerance_double) {
  Scene<double> scene = random_scene(c.camera, 60, c.degree, c.seed);
  scene.antialiased = c.antialiased;
  const ReferenceImage ref = reference_render(scene, c.camera, kRasterBackground);
  const float bg[3] = {float(kRasterBackground[0]), float(kRasterBackground[1]),
                       float(kRasterBackground[2])};
  const KernelRender<float> f = kernel_render(scene.cast<float>(), c.camera, bg);
  EXPECT_LT(max_abs_diff(f.image, ref.image), tolerance_float);
  EXPECT_LT(max_abs_diff(f.alpha, ref.alpha), tolerance_float);
  EXPECT_LT(max_abs_diff(f.depth, ref.depth), tolerance_float);
  // In double the kernels agree with the reference up to rounding: same cut-offs, same order.
  const KernelRender<double> d = kernel_render(scene, c.camera, kRasterBackground);
  EXPECT_LT(max_abs_diff(d.image, ref.image), tolerance_double);
  EXPECT_LT(max_abs_diff(d.alpha, ref.alpha), tolerance_double);
  EXPECT_LT(max_abs_diff(d.depth, ref.depth), tolerance_double);
}

TEST(RasterForward, MatchesReferenceOnRandomScenes) {
  // Sizes that are not multiples of the tile size exercise the partial border tiles.
  const std::vector<ReferenceCase> cases = {
      {test_camera(64, 48), 3, 1},       {posed_test_camera(70, 53), 3, 2},
      {posed_test_camera(33, 47), 1, 3}, {test_camera(96, 80), 0, 4},
      {posed_test_camera(64, 64), 2, 5}, {posed_test_camera(70, 53), 3, 6, false}};
  for (const ReferenceCase& c : cases) {
    SCOPED_TRACE(::testing::Message() << "seed " << c.seed);
    expect_matches_reference(c, 1e-4, 1e-12);
  }
}

TEST(RasterForward, EdgeCasesAreExercised) {
  // Guards the scene generator: the comparison above must actually meet every edge case.
  const Camera cam = test_camera(64, 48);
  const Scene<double> scene = random_scene(cam, 60, 3, 1);
  const KernelRender<double> d = kernel_render(scene, cam, kRasterBackground);
  const int first_edge = 60;
  EXPECT_EQ(d.radii[first_edge], 0);       // behind the camera
  EXPECT_EQ(d.radii[first_edge + 1], 0);   // in front of the near plane
  EXPECT_GT(d.radii[first_edge + 3], 0);   // beyond the Jacobian clamp but reaching the image
  EXPECT_EQ(d.radii[first_edge + 7], 0);   // opacity too low to be drawn
  EXPECT_GT(d.radii[first_edge + 6], 64);  // larger than the image
  EXPECT_GT(d.radii[first_edge + 9], 20);  // needle
  // The opaque stack stops pixels before its last Gaussian.
  const Intrinsics& k = cam.intrinsics;
  const size_t center = size_t(k.fy * -0.2 + k.cy) * k.width + size_t(k.fx * -0.25 + k.cx);
  EXPECT_LT(d.frame.final_transmittance[center], 1e-3);
  size_t stopped = 0;
  for (size_t i = 0; i < d.alpha.size(); ++i) stopped += d.frame.final_transmittance[i] < 2e-4;
  EXPECT_GT(stopped, 10u);
}

// Mip-Splatting's filter adds 0.1 px^2 and scales the opacity by the square root of the ratio of
// determinants; 3DGS's dilation adds 0.3 px^2 and leaves the opacity alone.
void expect_isotropic_closed_form(bool antialiased) {
  const Camera cam = test_camera(40, 40);
  const Intrinsics& k = cam.intrinsics;
  const double z = 4, scale = 0.3, opacity = 0.8, value = 0.7;
  Scene<double> s;
  s.antialiased = antialiased;
  // On the optical axis the Jacobian is diag(f / z): the splat is isotropic with std f s / z.
  const double dc = (value - 0.5) / 0.28209479177387814;
  s.add({0, 0, z}, {std::log(scale), std::log(scale), std::log(scale)}, {1, 0, 0, 0},
        std::log(opacity / (1 - opacity)), {dc, dc, dc}, 0);
  const KernelRender<double> r = kernel_render(s, cam, kRasterBackground);
  const double var = std::pow(k.fx * scale / z, 2), h = antialiased ? 0.1 : 0.3;
  const double filtered_opacity = antialiased ? opacity * var / (var + h) : opacity;
  const size_t plane = size_t(k.width) * k.height;
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x) {
      const double d2 = std::pow(x + 0.5 - k.cx, 2) + std::pow(y + 0.5 - k.cy, 2);
      double alpha = std::min(kAlphaCap, filtered_opacity * std::exp(-0.5 * d2 / (var + h)));
      if (alpha < kAlphaSkip) alpha = 0;
      const size_t i = size_t(y) * k.width + x;
      ASSERT_NEAR(r.alpha[i], alpha, 1e-12);
      ASSERT_NEAR(r.depth[i], alpha * z, 1e-12);
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(r.image[c * plane + i], alpha * value + (1 - alpha) * kRasterBackground[c],
                    1e-12);
    }
}

TEST(RasterForward, SingleIsotropicGaussianHasClosedForm) {
  expect_isotropic_closed_form(true);
}

TEST(RasterForward, ClassicDilationHasClosedForm) {
  expect_isotropic_closed_form(false);
}

TEST(RasterForward, CropRendersAsTheSamePixelsOfTheFullImage) {
  // The right half of the image is a camera whose principal point lies on its left edge. The
  // Gaussians near its right edge must not be clamped as if they were far outside the view.
  const Camera full = posed_test_camera(64, 48);
  Camera crop = full;
  const int offset = 32;
  crop.intrinsics.width = full.intrinsics.width - offset;
  crop.intrinsics.cx -= offset;
  Scene<double> s;
  s.sh_degree = 1;
  std::mt19937 rng(7);
  for (double u : {0.05, 0.2, 0.35, 0.45, 0.52})
    for (double v : {-0.3, 0.0, 0.3}) {
      const double z = 3 + u;
      s.add(world_point(full, u, v, z), {-2.6, -3.2, -2.9}, random_quat(rng), 1.0,
            {0.6 * u, -0.4 * v, 0.3}, 0.01, {0.2, -0.1, 0.3, 0.1, 0.2, -0.3, 0.05, 0.1, -0.2});
    }
  const KernelRender<double> whole = kernel_render(s, full, kRasterBackground);
  const KernelRender<double> part = kernel_render(s, crop, kRasterBackground);
  const Intrinsics& k = crop.intrinsics;
  const size_t plane = size_t(k.width) * k.height, full_plane = size_t(64) * k.height;
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < k.height; ++y)
      for (int x = 0; x < k.width; ++x)
        ASSERT_NEAR(part.image[c * plane + size_t(y) * k.width + x],
                    whole.image[c * full_plane + size_t(y) * 64 + x + offset], 1e-12)
            << "channel " << c << " pixel " << x << "," << y;
}

// Box-averages a (3 or 1, H, W) planar image by an integer factor.
std::vector<double> box_downsample(const std::vector<double>& in, int width, int height,
                                   int factor) {
  const int w = width / factor, h = height / factor;
  const int planes = int(in.size() / (size_t(width) * height));
  std::vector<double> out(size_t(planes) * w * h, 0);
  for (int p = 0; p < planes; ++p)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        out[(size_t(p) * h + y / factor) * w + x / factor] +=
            in[(size_t(p) * height + y) * width + x] / (factor * factor);
  return out;
}

TEST(RasterForward, SupersampledRenderMatchesAfterBoxFilter) {
  // Smooth, well-resolved Gaussians (several pixels wide at 1x): rendering at 4x with the same
  // field of view and box-averaging back must agree with the 1x render up to the difference
  // between the 1x mip filter and the box filter.
  const Camera cam = posed_test_camera(48, 40);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  Scene<double> s;
  s.sh_degree = 1;
  for (int i = 0; i < 25; ++i)
    s.add(world_point(cam, 0.5 * u(rng), 0.4 * u(rng), 4 + u(rng)), {-1.5, -1.6, -1.4},
          random_quat(rng), -0.5 + 0.5 * u(rng), {u(rng), u(rng), u(rng)}, 0.01,
          std::vector<double>(9, 0.1));
  const KernelRender<double> low = kernel_render(s, cam, kRasterBackground);
  const Camera high_cam = cam.scaled(4);
  const KernelRender<double> high = kernel_render(s, high_cam, kRasterBackground);
  const auto down =
      box_downsample(high.image, high_cam.intrinsics.width, high_cam.intrinsics.height, 4);
  double worst = 0, mean = 0;
  for (size_t i = 0; i < down.size(); ++i) {
    worst = std::max(worst, std::abs(down[i] - low.image[i]));
    mean += std::abs(down[i] - low.image[i]) / down.size();
  }
  EXPECT_LT(worst, 5e-3);
  EXPECT_LT(mean, 5e-4);
}

// Means and SH gradients of a uniform image gradient on the render r of s, written into arrays
// that held `stale` before.
std::vector<float> differentiate(const Scene<float>& s, KernelRender<float>& r, float stale = 0) {
  const std::vector<float> dimage(r.image.size(), 1.f);
  const size_t n = s.count();
  std::vector<float> dmeans(3 * n, stale), dscales(3 * n, stale), dquats(4 * n, stale),
      dlogits(n, stale), dsh_dc(3 * n, stale), dsh_rest(45 * n, stale);
  rasterize_backward(s.params(), r.frame, PixelGrads<float>{dimage.data()},
                     GaussianGrads<float>{dmeans.data(), dscales.data(), dquats.data(),
                                          dlogits.data(), dsh_dc.data(), dsh_rest.data()});
  dmeans.insert(dmeans.end(), dsh_dc.begin(), dsh_dc.end());
  dmeans.insert(dmeans.end(), dsh_rest.begin(), dsh_rest.end());
  return dmeans;
}

// The same, rendered and differentiated with `threads`.
std::vector<float> render_and_differentiate(const Scene<float>& s, const Camera& cam, int threads,
                                            KernelRender<float>& r) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  const float bg[3] = {0, 0, 0};
  r = kernel_render(s, cam, bg);
  std::vector<float> grads = differentiate(s, r);
  omp_set_num_threads(saved);
  return grads;
}

TEST(RasterForward, AReusedFrameRendersAsAFreshOne) {
  // Frames go back to a pool and serve later renders of any size: nothing of the scene before,
  // larger or smaller, may leak into the next one, forward or backward.
  const Camera big = posed_test_camera(80, 64), small = test_camera(24, 20);
  const Scene<float> many = random_scene(big, 300, 3, 11).cast<float>();
  const Scene<float> few = random_scene(small, 12, 1, 4).cast<float>();
  const float bg[3] = {0.2f, 0.4f, 0.6f};
  for (const auto& [before, before_cam, s, cam] :
       {std::tuple{&many, &big, &few, &small}, std::tuple{&few, &small, &many, &big}}) {
    KernelRender<float> earlier = kernel_render(*before, *before_cam, bg);
    differentiate(*before, earlier);
    KernelRender<float> reused = kernel_render(*s, *cam, bg, std::move(earlier.frame));
    KernelRender<float> fresh = kernel_render(*s, *cam, bg);
    EXPECT_EQ(reused.image, fresh.image);
    EXPECT_EQ(reused.alpha, fresh.alpha);
    EXPECT_EQ(reused.depth, fresh.depth);
    EXPECT_EQ(reused.radii, fresh.radii);
    EXPECT_EQ(differentiate(*s, reused), differentiate(*s, fresh));
  }
}

TEST(RasterBackward, OverwritesWhatTheGradientArraysHeld) {
  // The training loop hands the backward pass arrays from earlier steps; Gaussians off the view
  // or hidden must come back zero, not stale.
  const Camera cam = posed_test_camera(80, 64);
  const Scene<float> s = random_scene(cam, 300, 3, 7).cast<float>();
  const float bg[3] = {0, 0, 0};
  KernelRender<float> r = kernel_render(s, cam, bg);
  const std::vector<float> clean = differentiate(s, r);
  EXPECT_EQ(differentiate(s, r, std::numeric_limits<float>::quiet_NaN()), clean);
  EXPECT_EQ(differentiate(s, r, 42.f), clean);
}

TEST(RasterForward, DeterministicAcrossRunsAndThreadCounts) {
  // Forward and backward results do not depend on the thread count or on scheduling: tiles are
  // independent and per-Gaussian sums run in a fixed order.
  const Camera cam = posed_test_camera(80, 64);
  const Scene<float> s = random_scene(cam, 300, 3, 11).cast<float>();
  KernelRender<float> one, two, again;
  const std::vector<float> grads_one = render_and_differentiate(s, cam, 1, one);
  const std::vector<float> grads_two = render_and_differentiate(s, cam, 2, two);
  const std::vector<float> grads_again = render_and_differentiate(s, cam, 2, again);
  EXPECT_EQ(one.image, two.image);
  EXPECT_EQ(one.depth, two.depth);
  EXPECT_EQ(two.image, again.image);
  EXPECT_EQ(one.radii, two.radii);
  EXPECT_EQ(grads_one, grads_two);
  EXPECT_EQ(grads_two, grads_again);
}

TEST(RasterForward, RejectsInvalidInput) {
  Camera cam = test_camera(16, 16);
  Scene<float> s = random_scene(cam, 3, 3, 1).cast<float>();
  const float bg[3] = {0, 0, 0};
  s.sh_degree = 4;
  EXPECT_THROW(kernel_render(s, cam, bg), Error);
  s.sh_degree = 3;
  KernelRender<float> r = kernel_render(s, cam, bg);
  EXPECT_THROW(rasterize_forward(
                   s.params(), raster_camera<float>(cam), bg, r.frame,
                   RenderTargets<float>{r.image.data(), r.alpha.data(), r.depth.data(), nullptr}),
               Error);
  std::vector<float> grads(size_t(s.count()) * 64);
  float* d = grads.data();
  EXPECT_THROW(rasterize_backward(s.params(), r.frame, PixelGrads<float>{},
                                  GaussianGrads<float>{d, d, d, nullptr, d, d, nullptr, nullptr}),
               Error);
  cam.intrinsics.width = 0;
  EXPECT_THROW(kernel_render(s, cam, bg), Error);
}

TEST(RasterForward, DivergedGaussiansCoverNothing) {
  // Training that diverges leaves non-finite or huge parameters; each such Gaussian must be
  // culled, not turned into a box of every pixel (or of 2^31 of them), and the rest must render
  // as without it.
  const Camera cam = test_camera(24, 20);
  const Scene<float> healthy = random_scene(cam, 12, 1, 4).cast<float>();
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Scene<double> diverged;
  diverged.add({inf, 0, 3}, {-2, -2, -2}, {1, 0, 0, 0}, 2, {1, 0, 0}, 0);
  diverged.add({0, nan, 3}, {-2, -2, -2}, {1, 0, 0, 0}, 2, {1, 0, 0}, 0);
  diverged.add({1e30, 0, 3}, {-2, -2, -2}, {1, 0, 0, 0}, 2, {1, 0, 0}, 0);
  diverged.add({0, 0, 3}, {inf, -2, -2}, {1, 0, 0, 0}, 2, {1, 0, 0}, 0);
  diverged.add({0, 0, 3}, {-2, nan, -2}, {1, 0, 0, 0}, 2, {1, 0, 0}, 0);
  diverged.add({0, 0, 3}, {-2, -2, -2}, {1, 0, 0, 0}, nan, {1, 0, 0}, 0);
  Scene<float> mixed = healthy;
  const Scene<float> bad = diverged.cast<float>();
  for (auto [to, from] : {std::pair{&mixed.means, &bad.means},
                          {&mixed.log_scales, &bad.log_scales},
                          {&mixed.quats, &bad.quats},
                          {&mixed.opacity_logits, &bad.opacity_logits},
                          {&mixed.sh_dc, &bad.sh_dc},
                          {&mixed.sh_rest, &bad.sh_rest},
                          {&mixed.filter_std, &bad.filter_std}})
    to->insert(to->end(), from->begin(), from->end());

  const float bg[3] = {0.3f, 0.3f, 0.3f};
  const KernelRender<float> expected = kernel_render(healthy, cam, bg);
  const KernelRender<float> r = kernel_render(mixed, cam, bg);
  EXPECT_EQ(r.image, expected.image);
  EXPECT_EQ(r.alpha, expected.alpha);
  for (int i = healthy.count(); i < mixed.count(); ++i) EXPECT_EQ(r.radii[size_t(i)], 0) << i;
}

TEST(RasterForward, HugeFiniteGaussianKeepsAPositiveRadius) {
  // Extents beyond an int's range: densification's visibility (radius > 0) and its max screen
  // size pruning must still see the splat.
  const Camera cam = test_camera(16, 16);
  Scene<double> scene;
  scene.add({0, 0, 3}, {25, 25, 25}, {1, 0, 0, 0}, 2, {1, 0, 0}, 0);
  const float bg[3] = {0, 0, 0};
  const KernelRender<float> r = kernel_render(scene.cast<float>(), cam, bg);
  EXPECT_EQ(r.radii[0], 1 << 30);
}

TEST(RasterBackward, PackedGradsLayTheArraysEndToEnd) {
  const size_t n = 5;
  std::vector<float> buffer(packed_grads_size(n));
  const GaussianGrads<float> grads = packed_grads(buffer.data(), n);
  const float* next = buffer.data();
  for (const GradArray<float>& a : grad_arrays(grads, n)) {
    EXPECT_EQ(a.data, next);
    next += a.size;
  }
  EXPECT_EQ(next, buffer.data() + buffer.size());
  EXPECT_EQ(buffer.size(), n * (3 + 3 + 4 + 1 + 3 + gs::kShRestFloats + 2 + 2));
}

TEST(RasterForward, EmptySceneShowsBackground) {
  const Camera cam = test_camera(20, 17);
  const KernelRender<float> r =
      kernel_render(Scene<float>{}, cam, std::array<float, 3>{0.1f, 0.2f, 0.3f}.data());
  for (size_t i = 0; i < r.alpha.size(); ++i) {
    EXPECT_EQ(r.alpha[i], 0.f);
    EXPECT_EQ(r.image[i + r.alpha.size()], 0.2f);
  }
}

}  // namespace
}  // namespace iesrgs::raster::testkit
