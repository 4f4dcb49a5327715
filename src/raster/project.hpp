#pragma once
// Projection of one Gaussian to a screen-space splat, and its backward pass, following 3DGS
// (EWA splatting with the Jacobian clamped at 1.3 x tan(fov / 2)) with Mip-Splatting's 3D
// smoothing filter and 2D mip filter, or 3DGS's dilation for models trained without it. The
// backward pass recomputes the forward intermediates.
#include "gs/mip_filter.hpp"
#include "gs/sh.hpp"
#include "raster/geometry.hpp"
#include "raster/types.hpp"

namespace iesrgs::raster {

constexpr double kNearPlane = 0.2;  // Gaussians with camera z at or below are culled, as 3DGS
constexpr double kJacobianClamp = 1.3;
// Blending thresholds as float constants, so that the double instantiation cuts exactly where
// the float one does: e.g. two splats at the 0.99 cap leave a transmittance just below 1e-4 in
// float (the pixel stops) but just above it with a double 0.99.
constexpr float kMinAlpha = 1.0f / 255.0f;
constexpr float kMaxAlpha = 0.99f;
constexpr float kMinTransmittance = 1e-4f;

// Every intermediate of the projection that the backward pass needs.
template <typename T>
struct Projection {
  Vec3T<T> view;   // camera-space mean
  T scale[3];      // exp(log_scale)
  T var[3];        // effective variances after the 3D filter
  T opacity3d;     // 3D filter opacity factor
  T sigmoid;       // activated opacity
  Mat3T<T> rot;    // Gaussian rotation
  Mat3T<T> sigma;  // world-space covariance
  T tx, ty;        // camera x, y after clamping x / z and y / z
  bool clamped_x, clamped_y;
  T jw[2][3];        // J W: Jacobian of the projection times the camera rotation
  Sym2<T> cov;       // screen-space covariance before the 2D filter
  Sym2<T> filtered;  // after the 2D filter
  T opacity2d;       // 2D filter opacity factor
  Sym2<T> conic;     // inverse of filtered
  T filtered_det;    // det(filtered), computed without cancellation
};

template <typename T>
IESRGS_HD Mat3T<T> camera_rotation(const RasterCamera<T>& cam) {
  return mat3_from_rows(cam.rotation);
}

template <typename T>
IESRGS_HD Vec3T<T> camera_center(const RasterCamera<T>& cam) {
  const Vec3T<T> t{cam.translation[0], cam.translation[1], cam.translation[2]};
  return T(-1) * mul_transposed(camera_rotation(cam), t);
}

// det(cov + h I) = det(cov) + h tr(cov) + h^2 with det(cov) by Cauchy-Binet over
// cov = (J W R) diag(var) (J W R)^T: a sum of non-negative terms, accurate even for needle-like
// splats, where xx yy - xy^2 cancels. Used for loop bounds, which must not be too tight.
template <typename T>
IESRGS_HD T stable_filtered_det(const Projection<T>& p, T h) {
  T m[2][3];
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < 3; ++k)
      m[r][k] =
          p.jw[r][0] * p.rot.m[0][k] + p.jw[r][1] * p.rot.m[1][k] + p.jw[r][2] * p.rot.m[2][k];
  T det_cov = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      const T minor = m[0][i] * m[1][j] - m[0][j] * m[1][i];
      det_cov += p.var[i] * p.var[j] * minor * minor;
    }
  return det_cov + h * (p.cov.xx + p.cov.yy) + h * h;
}

// Fills p for Gaussian i; false when it is culled (behind the near plane or degenerate).
template <typename T>
IESRGS_HD bool project(const GaussianParams<T>& g, int i, const RasterCamera<T>& cam,
                       Projection<T>& p) {
  const Mat3T<T> w = camera_rotation(cam);
  const Vec3T<T> mean{g.means[3 * i], g.means[3 * i + 1], g.means[3 * i + 2]};
  p.view = mul(w, mean) + Vec3T<T>{cam.translation[0], cam.translation[1], cam.translation[2]};
  const T z = p.view.z;
  if (!(z > T(kNearPlane))) return false;  // also culls a non-finite mean

  for (int k = 0; k < 3; ++k) p.scale[k] = hd::exp(g.log_scales[3 * i + k]);
  p.opacity3d = gs::filter3d(p.scale, g.filter_std ? g.filter_std[i] : T(0), p.var);
  p.sigmoid = T(1) / (T(1) + hd::exp(-g.opacity_logits[i]));
  p.rot = quat_to_rotation(g.quats + 4 * i);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      T s = 0;
      for (int k = 0; k < 3; ++k) s += p.rot.m[r][k] * p.var[k] * p.rot.m[c][k];
      p.sigma.m[r][c] = s;
    }

  // The clamp keeps the linearization sane for Gaussians far outside the field of view.
  const T lim_x = T(kJacobianClamp) * T(cam.width) / (T(2) * cam.fx);
  const T lim_y = T(kJacobianClamp) * T(cam.height) / (T(2) * cam.fy);
  const T rx = p.view.x / z, ry = p.view.y / z;
  p.clamped_x = rx < -lim_x || rx > lim_x;
  p.clamped_y = ry < -lim_y || ry > lim_y;
  p.tx = hd::min(lim_x, hd::max(-lim_x, rx)) * z;
  p.ty = hd::min(lim_y, hd::max(-lim_y, ry)) * z;
  const T j[2][3] = {{cam.fx / z, 0, -cam.fx * p.tx / (z * z)},
                     {0, cam.fy / z, -cam.fy * p.ty / (z * z)}};
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c)
      p.jw[r][c] = j[r][0] * w.m[0][c] + j[r][1] * w.m[1][c] + j[r][2] * w.m[2][c];

  T cov[2][2];
  for (int r = 0; r < 2; ++r)
    for (int c = r; c < 2; ++c) {
      T s = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) s += p.jw[r][a] * p.sigma.m[a][b] * p.jw[c][b];
      cov[r][c] = s;
    }
  p.cov = {cov[0][0], cov[0][1], cov[1][1]};
  p.opacity2d = gs::filter2d(p.cov, g.antialiased, p.filtered);
  if (!(det(p.filtered) > T(0))) return false;
  p.conic = inverse(p.filtered);
  p.filtered_det = stable_filtered_det(p, T(gs::filter2d_variance(g.antialiased)));
  return true;
}

template <typename T>
IESRGS_HD Vec3T<T> view_direction(const GaussianParams<T>& g, int i, const RasterCamera<T>& cam) {
  return Vec3T<T>{g.means[3 * i], g.means[3 * i + 1], g.means[3 * i + 2]} - camera_center(cam);
}

template <typename T>
IESRGS_HD Splat<T> make_splat(const GaussianParams<T>& g, int i, const RasterCamera<T>& cam,
                              const Projection<T>& p) {
  Splat<T> s;
  s.x = cam.fx * p.view.x / p.view.z + cam.cx;
  s.y = cam.fy * p.view.y / p.view.z + cam.cy;
  s.conic_xx = p.conic.xx;
  s.conic_xy = p.conic.xy;
  s.conic_yy = p.conic.yy;
  s.opacity = p.sigmoid * p.opacity3d * p.opacity2d;
  gs::sh_to_color(g.sh_degree, g.sh + 3 * gs::kShCoefficients * i, view_direction(g, i, cam),
                  s.color);
  s.depth = p.view.z;
  // opacity * exp(-q / 2) >= 1/255 iff q <= 2 ln(255 opacity); a relative margin keeps rounding
  // at the border on the safe side.
  const T level = T(2) * hd::log(s.opacity / T(kMinAlpha));
  s.cutoff = level > T(0) ? level * T(1.001) + T(1e-3) : T(0);
  s.conic_det = T(1) / p.filtered_det;
  return s;
}

// Bounding box of the pixels whose alpha can reach 1/255. Unlike 3DGS's fixed 3 sigma this drops
// nothing the blending would keep (as gsplat), and shrinks faint splats. Empty when nothing can
// be seen.
template <typename T>
IESRGS_HD PixelRect splat_rect(const Splat<T>& s, const Projection<T>& p, int width, int height) {
  PixelRect rect{0, 0, 0, 0};
  const T hx = hd::sqrt(s.cutoff * p.filtered.xx), hy = hd::sqrt(s.cutoff * p.filtered.yy);
  // A diverged Gaussian (non-finite center or extent) covers nothing instead of every pixel.
  if (!(s.cutoff > T(0)) || !hd::isfinite(s.x + hx) || !hd::isfinite(s.y + hy)) return rect;
  // Pixel i has its center at i + 0.5; clamp to the image in floating point before converting,
  // so that a center far off screen cannot overflow an int.
  const auto clamp = [](T v, int hi) { return int(hd::min(T(hi), hd::max(T(0), v))); };
  rect.x0 = clamp(hd::ceil(s.x - hx - T(0.5)), width);
  rect.y0 = clamp(hd::ceil(s.y - hy - T(0.5)), height);
  rect.x1 = clamp(hd::floor(s.x + hx - T(0.5)) + T(1), width);
  rect.y1 = clamp(hd::floor(s.y + hy - T(0.5)) + T(1), height);
  if (rect.empty()) rect = {0, 0, 0, 0};
  return rect;
}

// Screen-space radius in pixels reported for densification (the larger half-extent of the box).
template <typename T>
IESRGS_HD int splat_radius(const Splat<T>& s, const Projection<T>& p) {
  return int(hd::ceil(hd::sqrt(s.cutoff * hd::max(p.filtered.xx, p.filtered.yy))));
}

// Accumulates into grads (row i of every array) the gradient of Gaussian i given the gradient of
// its splat. Viewspace gradients are written, not accumulated.
template <typename T>
IESRGS_HD void project_backward(const GaussianParams<T>& g, int i, const RasterCamera<T>& cam,
                                const SplatGrad<T>& ds, const GaussianGrads<T>& grads) {
  Projection<T> p;
  if (!project(g, i, cam, p)) return;
  const T z = p.view.z;
  const Mat3T<T> w = camera_rotation(cam);

  // Screen position and depth.
  Vec3T<T> dview{ds.x * cam.fx / z, ds.y * cam.fy / z,
                 ds.depth - (ds.x * cam.fx * p.view.x + ds.y * cam.fy * p.view.y) / (z * z)};
  if (grads.viewspace) {
    grads.viewspace[2 * i] = ds.x * T(0.5) * T(cam.width);
    grads.viewspace[2 * i + 1] = ds.y * T(0.5) * T(cam.height);
  }
  if (grads.viewspace_abs) {
    grads.viewspace_abs[2 * i] = ds.abs_x * T(0.5) * T(cam.width);
    grads.viewspace_abs[2 * i + 1] = ds.abs_y * T(0.5) * T(cam.height);
  }

  // Opacity = sigmoid * opacity3d * opacity2d.
  const T dsigmoid = ds.opacity * p.opacity3d * p.opacity2d;
  grads.opacity_logits[i] += dsigmoid * p.sigmoid * (T(1) - p.sigmoid);
  const T dopacity3d = ds.opacity * p.sigmoid * p.opacity2d;
  const T dopacity2d = ds.opacity * p.sigmoid * p.opacity3d;

  // Conic -> filtered covariance -> covariance.
  const Sym2<T> dfiltered =
      inverse_backward(p.conic, Sym2<T>{ds.conic_xx, ds.conic_xy, ds.conic_yy});
  const Sym2<T> dcov = gs::filter2d_backward(p.cov, g.antialiased, dfiltered, dopacity2d);
  const T g2[2][2] = {{dcov.xx, T(0.5) * dcov.xy}, {T(0.5) * dcov.xy, dcov.yy}};

  // cov = (J W) sigma (J W)^T: dsigma = (J W)^T g2 (J W), d(J W) = 2 g2 (J W) sigma.
  Mat3T<T> dsigma;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      T s = 0;
      for (int r = 0; r < 2; ++r)
        for (int c = 0; c < 2; ++c) s += p.jw[r][a] * g2[r][c] * p.jw[c][b];
      dsigma.m[a][b] = s;
    }
  T djw[2][3];
  for (int r = 0; r < 2; ++r)
    for (int b = 0; b < 3; ++b) {
      T s = 0;
      for (int c = 0; c < 2; ++c)
        for (int a = 0; a < 3; ++a) s += g2[r][c] * p.jw[c][a] * p.sigma.m[a][b];
      djw[r][b] = T(2) * s;
    }
  // J W: dJ = d(J W) W^T; only J00, J02, J11, J12 are nonzero.
  T dj[2][3];
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c)
      dj[r][c] = djw[r][0] * w.m[c][0] + djw[r][1] * w.m[c][1] + djw[r][2] * w.m[c][2];
  const T z2 = z * z, z3 = z2 * z;
  dview.z += -cam.fx / z2 * dj[0][0] - cam.fy / z2 * dj[1][1] +
             T(2) * cam.fx * p.tx / z3 * dj[0][2] + T(2) * cam.fy * p.ty / z3 * dj[1][2];
  const T dtx = -cam.fx / z2 * dj[0][2], dty = -cam.fy / z2 * dj[1][2];
  // tx = z * clamp(x / z): the clamped ratio is constant, so tx then scales with z.
  if (p.clamped_x)
    dview.z += dtx * p.tx / z;
  else
    dview.x += dtx;
  if (p.clamped_y)
    dview.z += dty * p.ty / z;
  else
    dview.y += dty;

  // sigma = R diag(var) R^T: dvar_k = (R^T dsigma R)_kk, dR = 2 dsigma R diag(var).
  T dvar[3];
  Mat3T<T> drot;
  for (int k = 0; k < 3; ++k) {
    T s = 0;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) s += p.rot.m[a][k] * dsigma.m[a][b] * p.rot.m[b][k];
    dvar[k] = s;
  }
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 3; ++k) {
      T s = 0;
      for (int b = 0; b < 3; ++b) s += dsigma.m[a][b] * p.rot.m[b][k];
      drot.m[a][k] = T(2) * s * p.var[k];
    }
  T dlog_scale[3];
  gs::filter3d_backward(p.scale, g.filter_std ? g.filter_std[i] : T(0), dvar, dopacity3d,
                        dlog_scale);
  for (int k = 0; k < 3; ++k) grads.log_scales[3 * i + k] += dlog_scale[k];
  T dq[4];
  quat_to_rotation_backward(g.quats + 4 * i, drot, dq);
  for (int k = 0; k < 4; ++k) grads.quats[4 * i + k] += dq[k];

  // Color through the spherical harmonics and the view direction.
  Vec3T<T> dmean = mul_transposed(w, dview);
  T dsh[3 * gs::kShCoefficients];
  gs::sh_to_color_backward(g.sh_degree, g.sh + 3 * gs::kShCoefficients * i,
                           view_direction(g, i, cam), ds.color, dsh, dmean);
  for (int k = 0; k < 3 * gs::kShCoefficients; ++k)
    grads.sh[3 * gs::kShCoefficients * i + k] += dsh[k];
  grads.means[3 * i] += dmean.x;
  grads.means[3 * i + 1] += dmean.y;
  grads.means[3 * i + 2] += dmean.z;
}

}  // namespace iesrgs::raster
