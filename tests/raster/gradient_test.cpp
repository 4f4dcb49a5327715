// Finite-difference checks of the backward pass, in double precision through the real kernels.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <functional>

#include "raster/cpu/kernels.hpp"
#include "raster_test_scene.hpp"

namespace iesrgs::raster::testkit {
namespace {

const double kGradientBackground[3] = {0.3, 0.6, 0.1};

// Finite differences render thousands of tiny frames: one thread avoids OpenMP start-up costs,
// which dominate on a busy machine.
class SingleThread {
 public:
  SingleThread() : saved_(omp_get_max_threads()) { omp_set_num_threads(1); }
  ~SingleThread() { omp_set_num_threads(saved_); }

 private:
  int saved_;
};

// A fixed random linear loss over image, alpha and depth.
struct LinearLoss {
  std::vector<double> image, alpha, depth;

  LinearLoss(size_t pixels, unsigned seed) : image(3 * pixels), alpha(pixels), depth(pixels) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    for (double& w : image) w = u(rng);
    for (double& w : alpha) w = u(rng);
    for (double& w : depth) w = 0.1 * u(rng);
  }
  double operator()(const KernelRender<double>& r) const {
    double sum = 0;
    for (size_t i = 0; i < image.size(); ++i) sum += image[i] * r.image[i];
    for (size_t i = 0; i < alpha.size(); ++i) sum += alpha[i] * r.alpha[i] + depth[i] * r.depth[i];
    return sum;
  }
};

// ||analytic - numeric|| / ||numeric|| over one parameter group, central differences.
double group_error(std::vector<double>& params, const std::vector<double>& analytic,
                   const std::function<double()>& loss) {
  const double h = 1e-6;
  double diff = 0, norm = 0;
  for (size_t i = 0; i < params.size(); ++i) {
    const double saved = params[i];
    params[i] = saved + h;
    const double up = loss();
    params[i] = saved - h;
    const double down = loss();
    params[i] = saved;
    const double numeric = (up - down) / (2 * h);
    diff += (numeric - analytic[i]) * (numeric - analytic[i]);
    norm += numeric * numeric;
  }
  EXPECT_GT(norm, 0) << "the check would pass vacuously";
  return std::sqrt(diff / norm);
}

struct Gradients {
  std::vector<double> means, log_scales, quats, logits, sh_dc, sh_rest, viewspace, viewspace_abs;
};

Gradients backward(const Scene<double>& s, KernelRender<double>& r, const LinearLoss& loss) {
  const size_t n = s.count();
  Gradients g{std::vector<double>(3 * n), std::vector<double>(3 * n), std::vector<double>(4 * n),
              std::vector<double>(n),     std::vector<double>(3 * n), std::vector<double>(45 * n),
              std::vector<double>(2 * n), std::vector<double>(2 * n)};
  rasterize_backward(s.params(), r.frame,
                     PixelGrads<double>{loss.image.data(), loss.alpha.data(), loss.depth.data()},
                     GaussianGrads<double>{g.means.data(), g.log_scales.data(), g.quats.data(),
                                           g.logits.data(), g.sh_dc.data(), g.sh_rest.data(),
                                           g.viewspace.data(), g.viewspace_abs.data()});
  return g;
}

void check_every_group(const Camera& cam, Scene<double> s, unsigned seed) {
  const SingleThread single_thread;
  const LinearLoss loss(size_t(cam.intrinsics.width) * cam.intrinsics.height, seed);
  KernelRender<double> r = kernel_render(s, cam, kGradientBackground);
  const Gradients g = backward(s, r, loss);
  const auto evaluate = [&] { return loss(kernel_render(s, cam, kGradientBackground)); };
  // Double precision puts the true error near 1e-8; a dropped term of the chain is far above
  // the bound even where it weighs little.
  const double bound = 1e-5;
  EXPECT_LT(group_error(s.means, g.means, evaluate), bound) << "means";
  EXPECT_LT(group_error(s.log_scales, g.log_scales, evaluate), bound) << "log-scales";
  EXPECT_LT(group_error(s.quats, g.quats, evaluate), bound) << "quaternions";
  EXPECT_LT(group_error(s.opacity_logits, g.logits, evaluate), bound) << "opacity logits";
  EXPECT_LT(group_error(s.sh_dc, g.sh_dc, evaluate), bound) << "SH band 0";
  if (s.sh_degree > 0) {  // degree 0 reads no higher band
    EXPECT_LT(group_error(s.sh_rest, g.sh_rest, evaluate), bound) << "SH bands 1-3";
  }
}

TEST(RasterBackward, MatchesFiniteDifferencesOnRandomScene) {
  const Camera cam = posed_test_camera(40, 32);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
  Scene<double> s;
  s.sh_degree = 3;
  for (int i = 0; i < 14; ++i) {
    std::vector<double> rest(45);
    for (double& x : rest) x = 0.2 * u(rng);
    const double size = std::log(0.08 + 0.15 * unit(rng));
    s.add(world_point(cam, 0.6 * u(rng), 0.5 * u(rng), 3 + 2 * unit(rng)),
          {size + 0.4 * u(rng), size + 0.4 * u(rng), size + 0.4 * u(rng)}, random_quat(rng),
          2 * u(rng), {u(rng), u(rng), u(rng)}, 0.02 * unit(rng), rest);
  }
  // Partly outside and beyond the Jacobian clamp, and an opaque one that saturates alpha.
  s.add(world_point(cam, 1.2, 0.1, 3), {-0.5, -0.9, -0.7}, random_quat(rng), 1, {0.3, -0.2, 0.5},
        0.01);
  s.add(world_point(cam, -0.1, 0.05, 2.5), {-1.8, -1.9, -1.7}, random_quat(rng), 7, {0.1, 0.2, 0.3},
        0.005);
  check_every_group(cam, s, 5);
}

TEST(RasterBackward, OffCentrePrincipalPointMatchesFiniteDifferences) {
  // The principal point 6 px left of the image, so that the clamp's bounds (x / z from 0.12 to
  // 1.65) are far from symmetric; one Gaussian beyond each reaches into the image.
  Camera cam = test_camera(24, 20);
  cam.intrinsics.cx = -6;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  Scene<double> s;
  s.sh_degree = 1;
  for (double x : {0.4, 0.7, 1.0, 1.3})
    s.add(world_point(cam, x, 0.3 * u(rng), 3 + u(rng)), {-2.2, -2.5, -2.3}, random_quat(rng),
          u(rng), {u(rng), u(rng), u(rng)}, 0.01, {0.1, -0.2, 0.1, 0.2, 0.1, -0.1, 0.3, 0.1, 0.2});
  for (double x : {0.0, 1.8})
    s.add(world_point(cam, x, 0.1, 3), {-0.5, -0.8, -0.6}, random_quat(rng), 0.5, {0.2, 0.4, -0.3},
          0.01);
  const KernelRender<double> r = kernel_render(s, cam, kGradientBackground);
  EXPECT_GT(r.radii[4], 0);  // beyond the bounds, yet drawn
  EXPECT_GT(r.radii[5], 0);
  check_every_group(cam, s, 51);
}

TEST(RasterBackward, MatchesFiniteDifferencesAtEveryShDegree) {
  const Camera cam = test_camera(24, 20);
  for (int degree = 0; degree <= 3; ++degree) {
    SCOPED_TRACE(degree);
    // Without the opaque stack: its pixels stop at the transmittance cut-off, a discontinuity
    // that finite differences must not straddle.
    const Scene<double> s = random_scene(cam, 8, degree, 20 + degree, false);
    check_every_group(cam, s, 40 + degree);
  }
}

// A 3D filter as wide as each Gaussian's first axis: the filter's opacity factor then weighs on
// the scales' gradients as much as the footprint does.
TEST(RasterBackward, WideThreeDFilterMatchesFiniteDifferences) {
  const Camera cam = posed_test_camera(24, 20);
  Scene<double> s = random_scene(cam, 10, 1, 37, false);
  for (size_t i = 0; i < s.filter_std.size(); ++i) s.filter_std[i] = std::exp(s.log_scales[3 * i]);
  check_every_group(cam, s, 38);
}

TEST(RasterBackward, ClassicDilationMatchesFiniteDifferences) {
  const Camera cam = posed_test_camera(24, 20);
  Scene<double> s = random_scene(cam, 10, 1, 31, false);
  s.antialiased = false;
  check_every_group(cam, s, 32);
}

// The blending stage alone against finite differences of the splat fields, which also checks
// the screen-space gradients reported for densification.
TEST(RasterBackward, SplatGradientsMatchFiniteDifferences) {
  const SingleThread single_thread;
  const Camera cam = posed_test_camera(40, 36);
  const Scene<double> s = random_scene(cam, 20, 2, 9);
  const LinearLoss loss(size_t(40) * 36, 13);
  KernelRender<double> r = kernel_render(s, cam, kGradientBackground);
  const Gradients g = backward(s, r, loss);
  RasterFrame<double>& frame = r.frame;
  const auto evaluate = [&] {
    cpu::blend_forward(frame, r.image.data(), r.alpha.data(), r.depth.data());
    return loss(r);
  };
  const double h = 1e-6;
  double worst = 0;
  int checked = 0;
  for (int i = 0; i < s.count(); ++i) {
    if (frame.rects[i].empty()) continue;
    Splat<double>& splat = frame.splats[i];
    const SplatGrad<double> analytic = frame.splat_grads[i];
    double* fields[] = {&splat.x,        &splat.y,       &splat.conic_xx, &splat.conic_xy,
                        &splat.conic_yy, &splat.opacity, &splat.color[0], &splat.depth};
    const double expected[] = {analytic.x,        analytic.y,        analytic.conic_xx,
                               analytic.conic_xy, analytic.conic_yy, analytic.opacity,
                               analytic.color[0], analytic.depth};
    for (int f = 0; f < 8; ++f) {
      const double saved = *fields[f];
      *fields[f] = saved + h;
      const double up = evaluate();
      *fields[f] = saved - h;
      const double down = evaluate();
      *fields[f] = saved;
      const double numeric = (up - down) / (2 * h);
      worst = std::max(worst, std::abs(numeric - expected[f]) / (std::abs(numeric) + 1e-3));
      ++checked;
    }
    // Viewspace gradients are the pixel-space ones in NDC units; the absolute variant bounds them.
    EXPECT_DOUBLE_EQ(g.viewspace[2 * i], analytic.x * 20);
    EXPECT_DOUBLE_EQ(g.viewspace[2 * i + 1], analytic.y * 18);
    EXPECT_GE(g.viewspace_abs[2 * i], std::abs(g.viewspace[2 * i]));
    EXPECT_GE(g.viewspace_abs[2 * i + 1], std::abs(g.viewspace[2 * i + 1]));
  }
  EXPECT_GT(checked, 80);
  EXPECT_LT(worst, 1e-4);
}

}  // namespace
}  // namespace iesrgs::raster::testkit
