#pragma once
// View-dependent color from real spherical harmonics up to degree 3, as 3DGS evaluates it:
// color = max(0, sum_k basis_k(dir) * sh_k + 0.5), dir the unit vector from the camera center to
// the Gaussian's mean. Coefficients are stored (16, 3) per Gaussian whatever the active degree,
// band 0 apart from the others as 3DGS models keep them (sh_dc (N, 1, 3), sh_rest (N, 15, 3)).
#include "core/geometry.hpp"

namespace iesrgs::gs {

constexpr int kShCoefficients = 16;  // degree 3
constexpr int kMaxShDegree = 3;
constexpr int kShRestFloats = 3 * (kShCoefficients - 1);  // bands 1..3 of one Gaussian

// One Gaussian's coefficients, or their gradients (T non-const): coefficient k of channel c.
template <typename T>
struct ShBands {
  T* dc;    // (3)
  T* rest;  // (15, 3)

  IESRGS_HD T& operator()(int k, int c) const { return k == 0 ? dc[c] : rest[3 * (k - 1) + c]; }
};

IESRGS_HD int sh_count(int degree) {
  return (degree + 1) * (degree + 1);
}

// Basis values b[k] at the unit direction (x, y, z) and, when grad != nullptr, their gradients
// grad[k] with respect to (x, y, z).
template <typename T>
IESRGS_HD void sh_basis(int degree, T x, T y, T z, T* b, Vec3T<T>* grad) {
  const T c0 = T(0.28209479177387814), c1 = T(0.4886025119029199);
  const T c2[5] = {T(1.0925484305920792), T(-1.0925484305920792), T(0.31539156525252005),
                   T(-1.0925484305920792), T(0.5462742152960396)};
  const T c3[7] = {T(-0.5900435899266435), T(2.890611442640554),   T(-0.4570457994644658),
                   T(0.3731763325901154),  T(-0.4570457994644658), T(1.445305721320277),
                   T(-0.5900435899266435)};
  b[0] = c0;
  if (grad) grad[0] = {0, 0, 0};
  if (degree < 1) return;
  b[1] = -c1 * y;
  b[2] = c1 * z;
  b[3] = -c1 * x;
  if (grad) {
    grad[1] = {0, -c1, 0};
    grad[2] = {0, 0, c1};
    grad[3] = {-c1, 0, 0};
  }
  if (degree < 2) return;
  const T xx = x * x, yy = y * y, zz = z * z;
  b[4] = c2[0] * x * y;
  b[5] = c2[1] * y * z;
  b[6] = c2[2] * (2 * zz - xx - yy);
  b[7] = c2[3] * x * z;
  b[8] = c2[4] * (xx - yy);
  if (grad) {
    grad[4] = {c2[0] * y, c2[0] * x, 0};
    grad[5] = {0, c2[1] * z, c2[1] * y};
    grad[6] = {-2 * c2[2] * x, -2 * c2[2] * y, 4 * c2[2] * z};
    grad[7] = {c2[3] * z, 0, c2[3] * x};
    grad[8] = {2 * c2[4] * x, -2 * c2[4] * y, 0};
  }
  if (degree < 3) return;
  b[9] = c3[0] * y * (3 * xx - yy);
  b[10] = c3[1] * x * y * z;
  b[11] = c3[2] * y * (4 * zz - xx - yy);
  b[12] = c3[3] * z * (2 * zz - 3 * xx - 3 * yy);
  b[13] = c3[4] * x * (4 * zz - xx - yy);
  b[14] = c3[5] * z * (xx - yy);
  b[15] = c3[6] * x * (xx - 3 * yy);
  if (grad) {
    grad[9] = {6 * c3[0] * x * y, 3 * c3[0] * (xx - yy), 0};
    grad[10] = {c3[1] * y * z, c3[1] * x * z, c3[1] * x * y};
    grad[11] = {-2 * c3[2] * x * y, c3[2] * (4 * zz - xx - 3 * yy), 8 * c3[2] * y * z};
    grad[12] = {-6 * c3[3] * x * z, -6 * c3[3] * y * z, 3 * c3[3] * (2 * zz - xx - yy)};
    grad[13] = {c3[4] * (4 * zz - 3 * xx - yy), -2 * c3[4] * x * y, 8 * c3[4] * x * z};
    grad[14] = {2 * c3[5] * x * z, -2 * c3[5] * y * z, c3[5] * (xx - yy)};
    grad[15] = {3 * c3[6] * (xx - yy), -6 * c3[6] * x * y, 0};
  }
}

// Color seen along `view` (camera center to mean, any length).
template <typename T>
IESRGS_HD void sh_to_color(int degree, ShBands<const T> sh, const Vec3T<T>& view, T* color) {
  const T inv = T(1) / hd::sqrt(dot(view, view));
  T b[kShCoefficients];
  sh_basis(degree, view.x * inv, view.y * inv, view.z * inv, b, static_cast<Vec3T<T>*>(nullptr));
  for (int c = 0; c < 3; ++c) {
    T sum = T(0.5);
    for (int k = 0; k < sh_count(degree); ++k) sum += b[k] * sh(k, c);
    color[c] = hd::max(sum, T(0));
  }
}

// Gradients of the coefficients (written to dsh, all 16 rows; rows beyond the degree get zero)
// and of `view` (added to dview) from dcolor. Channels clamped at zero pass no gradient.
template <typename T>
IESRGS_HD void sh_to_color_backward(int degree, ShBands<const T> sh, const Vec3T<T>& view,
                                    const T* dcolor, ShBands<T> dsh, Vec3T<T>& dview) {
  const T inv = T(1) / hd::sqrt(dot(view, view));
  const Vec3T<T> dir = inv * view;
  T b[kShCoefficients];
  Vec3T<T> db[kShCoefficients];
  sh_basis(degree, dir.x, dir.y, dir.z, b, db);
  const int count = sh_count(degree);
  T live[3];
  for (int c = 0; c < 3; ++c) {
    T sum = T(0.5);
    for (int k = 0; k < count; ++k) sum += b[k] * sh(k, c);
    live[c] = hd::select(sum < T(0), T(0), dcolor[c]);
  }
  Vec3T<T> ddir{0, 0, 0};
  for (int k = 0; k < kShCoefficients; ++k)
    for (int c = 0; c < 3; ++c) {
      dsh(k, c) = k < count ? b[k] * live[c] : T(0);
      if (k < count) ddir = ddir + (live[c] * sh(k, c)) * db[k];
    }
  // Through the normalization of the view direction.
  dview = dview + inv * (ddir - dot(ddir, dir) * dir);
}

}  // namespace iesrgs::gs
