#pragma once
// Projection of one Gaussian to a screen-space splat, and its backward pass, following 3DGS
// (EWA splatting with the Jacobian clamped near the image) with Mip-Splatting's 3D
// smoothing filter and 2D mip filter, or 3DGS's dilation for models trained without it. The
// backward pass recomputes the forward intermediates. T is float or double on one Gaussian, or a
// pack of floats with one Gaussian per SIMD lane (raster/cpu/lanes.hpp), hence no branch on data.
#include "core/geometry.hpp"
#include "gs/mip_filter.hpp"
#include "gs/sh.hpp"
#include "raster/blend_math.hpp"
#include "raster/types.hpp"

namespace iesrgs::raster {

// The Jacobian is taken no further out than this fraction of the image's half-width (height)
// beyond each edge: 3DGS's 1.3 x tan(fov / 2) for a centred principal point.
constexpr double kJacobianMargin = 0.3;
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
  hd::Mask<T> clamped_x, clamped_y;
  T jw[2][3];        // J W: Jacobian of the projection times the camera rotation
  Sym2<T> cov;       // screen-space covariance before the 2D filter
  Sym2<T> filtered;  // after the 2D filter
  T opacity2d;       // 2D filter opacity factor
  Sym2<T> conic;     // inverse of filtered
  T filtered_det;    // det(filtered), computed without cancellation
};

// One Gaussian's parameters as the projection reads them: row i of GaussianParams in place, or,
// with T a SIMD pack, one Gaussian per lane (raster/cpu/project_packs.cpp).
template <typename T>
struct GaussianRow {
  Vec3T<T> mean;
  const T* log_scale;  // (3)
  const T* quat;       // (4)
  T opacity_logit;
  T filter_std;  // 0 without the 3D filter
  gs::ShBands<const T> sh;
  int sh_degree;
  bool antialiased;
};

template <typename T>
IESRGS_HD GaussianRow<T> gaussian_row(const GaussianParams<T>& g, int i) {
  return {{g.means[3 * i], g.means[3 * i + 1], g.means[3 * i + 2]},
          g.log_scales + 3 * i,
          g.quats + 4 * i,
          g.opacity_logits[i],
          g.filter_std ? g.filter_std[i] : T(0),
          {g.sh_dc + 3 * i, g.sh_rest + gs::kShRestFloats * size_t(i)},
          g.sh_degree,
          g.antialiased};
}

// The gradient of one GaussianRow, and the screen-space gradients that drive densification.
template <typename T>
struct GaussianRowGrad {
  Vec3T<T> mean;
  T log_scale[3];
  T quat[4];
  T opacity_logit;
  T sh_dc[3];
  T sh_rest[gs::kShRestFloats];
  T viewspace[2], viewspace_abs[2];
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

// Fills p for one Gaussian (or one per lane); false where it is culled (behind the near plane or
// degenerate). Branch-free, so that it runs on SIMD packs: culled lanes compute garbage that the
// result masks.
template <typename T>
IESRGS_HD hd::Mask<T> project(const GaussianRow<T>& g, const RasterCamera<T>& cam,
                              Projection<T>& p) {
  const Mat3T<T> w = camera_rotation(cam);
  p.view = mul(w, g.mean) + Vec3T<T>{cam.translation[0], cam.translation[1], cam.translation[2]};
  const T z = p.view.z;
  hd::Mask<T> visible = z > T(gs::kNearPlane);  // also culls a non-finite mean

  for (int k = 0; k < 3; ++k) p.scale[k] = hd::exp(g.log_scale[k]);
  p.opacity3d = gs::filter3d(p.scale, g.filter_std, p.var);
  p.sigmoid = T(1) / (T(1) + hd::exp(-g.opacity_logit));
  p.rot = quat_to_rotation(g.quat);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      T s = 0;
      for (int k = 0; k < 3; ++k) s += p.rot.m[r][k] * p.var[k] * p.rot.m[c][k];
      p.sigma.m[r][c] = s;
    }

  // The clamp keeps the linearization sane for Gaussians far outside the field of view. Its bounds
  // are the image edges as seen from the principal point (as gsplat's), so that an off-centre
  // one does not clamp Gaussians inside the image.
  const T margin_x = T(kJacobianMargin / 2) * T(cam.width) / cam.fx;
  const T margin_y = T(kJacobianMargin / 2) * T(cam.height) / cam.fy;
  const T lo_x = -cam.cx / cam.fx - margin_x, hi_x = (T(cam.width) - cam.cx) / cam.fx + margin_x;
  const T lo_y = -cam.cy / cam.fy - margin_y, hi_y = (T(cam.height) - cam.cy) / cam.fy + margin_y;
  const T rx = p.view.x / z, ry = p.view.y / z;
  p.clamped_x = rx < lo_x || rx > hi_x;
  p.clamped_y = ry < lo_y || ry > hi_y;
  p.tx = hd::min(hi_x, hd::max(lo_x, rx)) * z;
  p.ty = hd::min(hi_y, hd::max(lo_y, ry)) * z;
  const T j[2][3] = {{cam.fx / z, T(0), -cam.fx * p.tx / (z * z)},
                     {T(0), cam.fy / z, -cam.fy * p.ty / (z * z)}};
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
  visible = visible && det(p.filtered) > T(0);
  p.conic = inverse(p.filtered);
  p.filtered_det = stable_filtered_det(p, T(gs::filter2d_variance(g.antialiased)));
  return visible;
}

// Fills p for Gaussian i of g; false when it is culled.
template <typename T>
IESRGS_HD bool project(const GaussianParams<T>& g, int i, const RasterCamera<T>& cam,
                       Projection<T>& p) {
  return project(gaussian_row(g, i), cam, p);
}

template <typename T>
IESRGS_HD Splat<T> make_splat(const GaussianRow<T>& g, const RasterCamera<T>& cam,
                              const Projection<T>& p) {
  Splat<T> s;
  s.x = cam.fx * p.view.x / p.view.z + cam.cx;
  s.y = cam.fy * p.view.y / p.view.z + cam.cy;
  s.conic_xx = p.conic.xx;
  s.conic_xy = p.conic.xy;
  s.conic_yy = p.conic.yy;
  s.opacity = p.sigmoid * p.opacity3d * p.opacity2d;
  gs::sh_to_color(g.sh_degree, g.sh, g.mean - camera_center(cam), s.color);
  s.depth = p.view.z;
  // opacity * exp(-q / 2) >= 1/255 iff q <= 2 ln(255 opacity); a relative margin keeps rounding
  // at the border on the safe side.
  const T level = T(2) * hd::log(s.opacity / T(kMinAlpha));
  s.cutoff = hd::select(level > T(0), level * T(1.001) + T(1e-3), T(0));
  s.conic_det = T(1) / p.filtered_det;
  return s;
}

template <typename T>
IESRGS_HD Splat<T> make_splat(const GaussianParams<T>& g, int i, const RasterCamera<T>& cam,
                              const Projection<T>& p) {
  return make_splat(gaussian_row(g, i), cam, p);
}

template <typename T>
struct SplatBounds {
  T x0, y0, x1, y1;  // pixels [x0, x1) x [y0, y1), clamped to the image
  // Reported for densification: the larger half-extent of the box. Being the extent where alpha
  // reaches 1/255, not 3DGS's 3 sigma, it is smaller for faint splats, which max_screen_size sees;
  // and a view where it is zero (a splat too faint to draw anywhere, as after an opacity reset)
  // is not counted in the mean view-space gradient, where 3DGS counts every view its 3-sigma box
  // reaches.
  T radius;
};

// Bounding box of the pixels whose alpha can reach 1/255. Unlike 3DGS's fixed 3 sigma this drops
// nothing the blending would keep (as gsplat), and shrinks faint splats. All zero where nothing
// can be seen. Branch-free like project(); splat_rect converts the bounds to ints.
template <typename T>
IESRGS_HD void splat_bounds(const Splat<T>& s, const Sym2<T>& filtered, int width, int height,
                            SplatBounds<T>& b) {
  const T hx = hd::sqrt(s.cutoff * filtered.xx), hy = hd::sqrt(s.cutoff * filtered.yy);
  // Pixel i has its center at i + 0.5; clamp to the image in floating point before converting,
  // so that a center far off screen cannot overflow an int.
  const auto clamp = [](T v, int hi) { return hd::min(T(hi), hd::max(T(0), v)); };
  b.x0 = clamp(hd::ceil(s.x - hx - T(0.5)), width);
  b.y0 = clamp(hd::ceil(s.y - hy - T(0.5)), height);
  b.x1 = clamp(hd::floor(s.x + hx - T(0.5)) + T(1), width);
  b.y1 = clamp(hd::floor(s.y + hy - T(0.5)) + T(1), height);
  // Capped so that a diverged but finite extent still converts to an int (splat_rect).
  b.radius = hd::min(hd::ceil(hd::max(hx, hy)), T(1 << 30));
  // A diverged Gaussian (non-finite center or extent) covers nothing instead of every pixel.
  const auto finite = [](T v) { return T(-INFINITY) < v && v < T(INFINITY); };
  const auto seen = T(0) < s.cutoff && finite(s.x + hx) && finite(s.y + hy);
  T* const bounds[] = {&b.x0, &b.y0, &b.x1, &b.y1, &b.radius};
  for (T* bound : bounds) *bound = hd::select(seen, *bound, T(0));
}

// The pixel rectangle and radius of the bounds of a visible splat (one that project() keeps);
// both zero otherwise, or when the rectangle is empty.
template <typename T>
IESRGS_HD void splat_rect(bool visible, const SplatBounds<T>& b, PixelRect& rect, int32_t& radius) {
  rect = {0, 0, 0, 0};
  radius = 0;
  if (!visible) return;  // its bounds are undefined
  const PixelRect r{int32_t(b.x0), int32_t(b.y0), int32_t(b.x1), int32_t(b.y1)};
  if (r.empty()) return;
  rect = r;
  radius = int32_t(b.radius);
}

template <typename T>
IESRGS_HD void splat_rect(const Splat<T>& s, const Sym2<T>& filtered, int width, int height,
                          PixelRect& rect, int32_t& radius) {
  SplatBounds<T> b;
  splat_bounds(s, filtered, width, height, b);
  splat_rect(true, b, rect, radius);
}

// cov = (J W) sigma (J W)^T, with g2 the gradient of cov as a symmetric matrix (its off-diagonal
// entry halved): dsigma = (J W)^T g2 (J W), d(J W) = 2 g2 (J W) sigma.
template <typename T>
IESRGS_HD void projected_covariance_backward(const Projection<T>& p, const T (&g2)[2][2],
                                             Mat3T<T>& dsigma, T (&djw)[2][3]) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      T s = 0;
      for (int r = 0; r < 2; ++r)
        for (int c = 0; c < 2; ++c) s += p.jw[r][a] * g2[r][c] * p.jw[c][b];
      dsigma.m[a][b] = s;
    }
  for (int r = 0; r < 2; ++r)
    for (int b = 0; b < 3; ++b) {
      T s = 0;
      for (int c = 0; c < 2; ++c)
        for (int a = 0; a < 3; ++a) s += g2[r][c] * p.jw[c][a] * p.sigma.m[a][b];
      djw[r][b] = T(2) * s;
    }
}

// J W: dJ = d(J W) W^T, of which only J00, J02, J11, J12 are nonzero, added to the gradient of
// the view-space position J depends on.
template <typename T>
IESRGS_HD void jacobian_backward(const Projection<T>& p, const RasterCamera<T>& cam,
                                 const Mat3T<T>& w, const T (&djw)[2][3], Vec3T<T>& dview) {
  T dj[2][3];
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c)
      dj[r][c] = djw[r][0] * w.m[c][0] + djw[r][1] * w.m[c][1] + djw[r][2] * w.m[c][2];
  const T z = p.view.z, z2 = z * z, z3 = z2 * z;
  dview.z += -cam.fx / z2 * dj[0][0] - cam.fy / z2 * dj[1][1] +
             T(2) * cam.fx * p.tx / z3 * dj[0][2] + T(2) * cam.fy * p.ty / z3 * dj[1][2];
  const T dtx = -cam.fx / z2 * dj[0][2], dty = -cam.fy / z2 * dj[1][2];
  // tx = z * clamp(x / z): the clamped ratio is constant, so tx then scales with z.
  dview.z += hd::select(p.clamped_x, dtx * p.tx / z, T(0));
  dview.x += hd::select(p.clamped_x, T(0), dtx);
  dview.z += hd::select(p.clamped_y, dty * p.ty / z, T(0));
  dview.y += hd::select(p.clamped_y, T(0), dty);
}

// sigma = R diag(var) R^T: dvar_k = (R^T dsigma R)_kk, dR = 2 dsigma R diag(var).
template <typename T>
IESRGS_HD void covariance_backward(const Projection<T>& p, const Mat3T<T>& dsigma, T (&dvar)[3],
                                   Mat3T<T>& drot) {
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
}

// The gradient of one Gaussian (or one per lane) given the gradient of its splat; false where it
// is culled, which gets no gradient. Branch-free like project().
template <typename T>
IESRGS_HD hd::Mask<T> project_backward(const GaussianRow<T>& g, const RasterCamera<T>& cam,
                                       const SplatGrad<T>& ds, GaussianRowGrad<T>& out) {
  Projection<T> p;
  const hd::Mask<T> visible = project(g, cam, p);
  const T z = p.view.z;
  const Mat3T<T> w = camera_rotation(cam);

  // Screen position and depth.
  Vec3T<T> dview{ds.x * cam.fx / z, ds.y * cam.fy / z,
                 ds.depth - (ds.x * cam.fx * p.view.x + ds.y * cam.fy * p.view.y) / (z * z)};
  out.viewspace[0] = ds.x * T(0.5) * T(cam.width);
  out.viewspace[1] = ds.y * T(0.5) * T(cam.height);
  out.viewspace_abs[0] = ds.abs_x * T(0.5) * T(cam.width);
  out.viewspace_abs[1] = ds.abs_y * T(0.5) * T(cam.height);

  // Opacity = sigmoid * opacity3d * opacity2d.
  const T dsigmoid = ds.opacity * p.opacity3d * p.opacity2d;
  out.opacity_logit = dsigmoid * p.sigmoid * (T(1) - p.sigmoid);
  const T dopacity3d = ds.opacity * p.sigmoid * p.opacity2d;
  const T dopacity2d = ds.opacity * p.sigmoid * p.opacity3d;

  // Conic -> filtered covariance -> covariance.
  const Sym2<T> dfiltered =
      inverse_backward(p.conic, Sym2<T>{ds.conic_xx, ds.conic_xy, ds.conic_yy});
  const Sym2<T> dcov = gs::filter2d_backward(p.cov, g.antialiased, dfiltered, dopacity2d);
  const T g2[2][2] = {{dcov.xx, T(0.5) * dcov.xy}, {T(0.5) * dcov.xy, dcov.yy}};

  // Covariance -> J W and sigma; J W -> view-space position; sigma -> scales and rotation.
  Mat3T<T> dsigma;
  T djw[2][3];
  projected_covariance_backward(p, g2, dsigma, djw);
  jacobian_backward(p, cam, w, djw, dview);
  T dvar[3];
  Mat3T<T> drot;
  covariance_backward(p, dsigma, dvar, drot);
  gs::filter3d_backward(p.scale, g.filter_std, dvar, dopacity3d, out.log_scale);
  quat_to_rotation_backward(g.quat, drot, out.quat);

  // Color through the spherical harmonics and the view direction.
  out.mean = mul_transposed(w, dview);
  gs::sh_to_color_backward(g.sh_degree, g.sh, g.mean - camera_center(cam), ds.color,
                           gs::ShBands<T>{out.sh_dc, out.sh_rest}, out.mean);
  return visible;
}

// Adds d to row i of every array of grads; the viewspace gradients are written, not added.
template <typename T>
IESRGS_HD void add_row_grad(const GaussianRowGrad<T>& d, int i, const GaussianGrads<T>& grads) {
  if (grads.viewspace) {
    grads.viewspace[2 * i] = d.viewspace[0];
    grads.viewspace[2 * i + 1] = d.viewspace[1];
  }
  if (grads.viewspace_abs) {
    grads.viewspace_abs[2 * i] = d.viewspace_abs[0];
    grads.viewspace_abs[2 * i + 1] = d.viewspace_abs[1];
  }
  grads.opacity_logits[i] += d.opacity_logit;
  for (int k = 0; k < 3; ++k) grads.log_scales[3 * i + k] += d.log_scale[k];
  for (int k = 0; k < 4; ++k) grads.quats[4 * i + k] += d.quat[k];
  for (int k = 0; k < 3; ++k) grads.sh_dc[3 * i + k] += d.sh_dc[k];
  for (int k = 0; k < gs::kShRestFloats; ++k)
    grads.sh_rest[gs::kShRestFloats * size_t(i) + k] += d.sh_rest[k];
  grads.means[3 * i] += d.mean.x;
  grads.means[3 * i + 1] += d.mean.y;
  grads.means[3 * i + 2] += d.mean.z;
}

// Adds to grads the gradient of Gaussian i given the gradient of its splat.
template <typename T>
IESRGS_HD void project_backward(const GaussianParams<T>& g, int i, const RasterCamera<T>& cam,
                                const SplatGrad<T>& ds, const GaussianGrads<T>& grads) {
  GaussianRowGrad<T> d;
  if (project_backward(gaussian_row(g, i), cam, ds, d)) add_row_grad(d, i, grads);
}

}  // namespace iesrgs::raster
