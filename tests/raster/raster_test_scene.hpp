#pragma once
// Random Gaussian scenes and cameras for the rasterizer tests.
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "gs/sh.hpp"
#include "io/camera.hpp"
#include "raster/rasterizer.hpp"
#include "support/compare.hpp"

namespace iesrgs::raster::testkit {

// GaussianBuffers in any scalar type, built one Gaussian at a time.
template <typename T>
struct Scene : GaussianBuffers<T> {
  Scene() { this->sh_degree = 0; }

  template <typename U>
  Scene<U> cast() const {
    const auto conv = [](const std::vector<T>& v) { return std::vector<U>(v.begin(), v.end()); };
    Scene<U> s;
    s.sh_degree = this->sh_degree;
    s.means = conv(this->means);
    s.log_scales = conv(this->log_scales);
    s.quats = conv(this->quats);
    s.opacity_logits = conv(this->opacity_logits);
    s.sh_dc = conv(this->sh_dc);
    s.sh_rest = conv(this->sh_rest);
    s.filter_std = conv(this->filter_std);
    s.antialiased = this->antialiased;
    return s;
  }
  // Appends one Gaussian; `dc` sets SH band 0 (the base color), `rest` the higher bands (zero
  // where it ends).
  void add(const Vec3& mean, const Vec3& log_scale, const std::array<double, 4>& quat, double logit,
           const std::array<double, 3>& dc, double filter, const std::vector<double>& rest = {}) {
    for (int k = 0; k < 3; ++k) {
      this->means.push_back(T(mean[k]));
      this->log_scales.push_back(T(log_scale[k]));
    }
    for (double q : quat) this->quats.push_back(T(q));
    this->opacity_logits.push_back(T(logit));
    for (double c : dc) this->sh_dc.push_back(T(c));
    for (size_t r = 0; r < size_t(gs::kShRestFloats); ++r)
      this->sh_rest.push_back(T(r < rest.size() ? rest[r] : 0.0));
    this->filter_std.push_back(T(filter));
  }
};

// A camera at the origin looking down +z (world = camera frame), fov about 60 degrees.
inline Camera test_camera(int width, int height) {
  Camera cam;
  cam.intrinsics.width = width;
  cam.intrinsics.height = height;
  cam.intrinsics.fx = cam.intrinsics.fy = 0.85 * width;
  cam.intrinsics.cx = 0.5 * width + 0.3;
  cam.intrinsics.cy = 0.5 * height - 0.2;
  return cam;
}

// The same view from a rotated and translated pose, so that R and t are not trivial.
inline Camera posed_test_camera(int width, int height) {
  Camera cam = test_camera(width, height);
  const double n = std::sqrt(0.97 * 0.97 + 0.1 * 0.1 + 0.2 * 0.2 + 0.05 * 0.05);
  cam.rotation = iesrgs::quat_to_rotation(0.97 / n, 0.1 / n, -0.2 / n, 0.05 / n);
  // Keep the scene at camera z in [2, 8]: the world origin maps to camera (0.1, -0.2, 5).
  cam.translation = Vec3{0.1, -0.2, 5.0};
  return cam;
}

// World point that the camera sees at normalized image coordinates (u, v) and depth z.
inline Vec3 world_point(const Camera& cam, double u, double v, double z) {
  const Vec3 camera_point{u * z, v * z, z};
  return cam.rotation.transposed() * (camera_point - cam.translation);
}

inline std::array<double, 4> random_quat(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  return {n(rng), n(rng), n(rng), n(rng)};
}

// Random scene with the edge cases the kernels must get right: Gaussians behind the camera or
// in front of the near plane, partly or far outside the frame (beyond the Jacobian clamp),
// sub-pixel, needle-like and image-covering sizes, opacities near 0 and 1, and optionally an
// opaque stack that drives the transmittance below its cut-off.
inline Scene<double> random_scene(const Camera& cam, int count, int degree, unsigned seed,
                                  bool opaque_stack = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), unit(0, 1);
  Scene<double> s;
  s.sh_degree = degree;
  const auto rest = [&] {
    std::vector<double> r(3 * (gs::kShCoefficients - 1));
    for (double& x : r) x = 0.15 * u(rng);
    return r;
  };
  const auto color = [&] { return std::array<double, 3>{u(rng), u(rng), u(rng)}; };
  for (int i = 0; i < count; ++i) {
    const Vec3 mean = world_point(cam, 0.8 * u(rng), 0.6 * u(rng), 2 + 6 * unit(rng));
    const double size = std::log(0.02 + 0.25 * unit(rng));
    const Vec3 log_scale{size + 0.5 * u(rng), size + 0.5 * u(rng), size + 0.5 * u(rng)};
    s.add(mean, log_scale, random_quat(rng), 3 * u(rng), color(), 0.01 * unit(rng), rest());
  }
  const Vec3 small{-6, -6, -6}, tiny{-3.8, -3.9, -3.7}, huge{1.2, 1.0, 1.3};
  s.add(world_point(cam, 0.1, 0.1, -3), {0, 0, 0}, {1, 0, 0, 0}, 4, color(), 0);       // behind
  s.add(world_point(cam, 0.1, 0.1, 0.15), {-2, -2, -2}, {1, 0, 0, 0}, 4, color(), 0);  // near
  s.add(world_point(cam, 0.95, -0.4, 3), {-1, -1.5, -1}, random_quat(rng), 2, color(), 0);
  s.add(world_point(cam, 1.6, 0.3, 4), {0.5, 0.2, 0.3}, random_quat(rng), 1, color(), 0);
  s.add(world_point(cam, -0.2, 0.1, 4), small, random_quat(rng), 5, color(), 0.002);
  s.add(world_point(cam, 0.3, -0.2, 5), tiny, random_quat(rng), 6, color(), 0.001);
  s.add(world_point(cam, 0.0, 0.05, 7), huge, random_quat(rng), 0.5, color(), 0.01);
  s.add(world_point(cam, -0.3, 0.2, 3), {-1.5, -1.5, -1.5}, random_quat(rng), -6, color(), 0);
  s.add(world_point(cam, 0.3, 0.25, 3), {-1.8, -1.6, -1.7}, random_quat(rng), 9, color(), 0);
  // Needles: one long axis, two sub-pixel ones, the hardest case for footprint bounds. Depths
  // differ from the others, so that finite differences never swap the blending order.
  s.add(world_point(cam, 0.05, -0.1, 4.37), {0.2, -4.5, -4.2}, random_quat(rng), 3, color(), 0);
  s.add(world_point(cam, -0.3, 0.3, 3.21), {-5, -0.8, -5.5}, random_quat(rng), 5, color(), 0);
  for (int k = 0; opaque_stack && k < 24; ++k)
    s.add(world_point(cam, -0.25 + 0.01 * u(rng), -0.2 + 0.01 * u(rng), 2.5 + 0.05 * k),
          {-1.6, -1.7, -1.5}, random_quat(rng), 6, color(), 0.001, rest());
  return s;
}

// A forward pass of the kernels with its outputs and frame (for a backward pass).
template <typename T>
struct KernelRender {
  std::vector<T> image, alpha, depth;
  std::vector<int32_t> radii;
  RasterFrame<T> frame;
};

// `frame` may hold an earlier render's buffers, as the frames that autograd takes from its pool.
template <typename T>
KernelRender<T> kernel_render(const Scene<T>& s, const Camera& cam, const T background[3],
                              RasterFrame<T> frame = {}) {
  KernelRender<T> r;
  r.frame = std::move(frame);
  const size_t plane = size_t(cam.intrinsics.width) * cam.intrinsics.height;
  r.image.assign(3 * plane, T(-1));
  r.alpha.assign(plane, T(-1));
  r.depth.assign(plane, T(-1));
  r.radii.assign(s.count(), -1);
  rasterize_forward(
      s.params(), raster_camera<T>(cam), background, r.frame,
      RenderTargets<T>{r.image.data(), r.alpha.data(), r.depth.data(), r.radii.data()});
  return r;
}

using iesrgs::testing::max_abs_diff;

}  // namespace iesrgs::raster::testkit
