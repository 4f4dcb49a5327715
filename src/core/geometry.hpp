#pragma once
// Fixed-size vectors and matrices for the kernels' math, templated on the scalar so that the same
// kernels run in float (production) and double (gradient checks).
#include "core/hd.hpp"

namespace iesrgs {

template <typename T>
struct Vec3T {
  T x, y, z;
};

template <typename T>
IESRGS_HD Vec3T<T> operator+(const Vec3T<T>& a, const Vec3T<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <typename T>
IESRGS_HD Vec3T<T> operator-(const Vec3T<T>& a, const Vec3T<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <typename T>
IESRGS_HD Vec3T<T> operator*(T s, const Vec3T<T>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <typename T>
IESRGS_HD T dot(const Vec3T<T>& a, const Vec3T<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

// Row-major 3x3.
template <typename T>
struct Mat3T {
  T m[3][3];
};

template <typename T>
IESRGS_HD Mat3T<T> mat3_from_rows(const T* rows) {
  Mat3T<T> r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = rows[3 * i + j];
  return r;
}

template <typename T>
IESRGS_HD Vec3T<T> mul(const Mat3T<T>& a, const Vec3T<T>& v) {
  return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
          a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
          a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}

// a^T v
template <typename T>
IESRGS_HD Vec3T<T> mul_transposed(const Mat3T<T>& a, const Vec3T<T>& v) {
  return {a.m[0][0] * v.x + a.m[1][0] * v.y + a.m[2][0] * v.z,
          a.m[0][1] * v.x + a.m[1][1] * v.y + a.m[2][1] * v.z,
          a.m[0][2] * v.x + a.m[1][2] * v.y + a.m[2][2] * v.z};
}

// Symmetric 2x2 [[xx, xy], [xy, yy]]. As a gradient, xy holds the derivative with respect to the
// one shared off-diagonal parameter (both entries together).
template <typename T>
struct Sym2 {
  T xx, xy, yy;
};

template <typename T>
IESRGS_HD T det(const Sym2<T>& a) {
  return a.xx * a.yy - a.xy * a.xy;
}

// Inverse of a (det(a) != 0).
template <typename T>
IESRGS_HD Sym2<T> inverse(const Sym2<T>& a) {
  const T inv_det = T(1) / det(a);
  return {a.yy * inv_det, -a.xy * inv_det, a.xx * inv_det};
}

// Gradient through k = a^-1: dL/da = -k (dL/dk) k, with the parameter convention above.
template <typename T>
IESRGS_HD Sym2<T> inverse_backward(const Sym2<T>& k, const Sym2<T>& dk) {
  // Full symmetric matrix of the upstream gradient.
  const T g00 = dk.xx, g01 = T(0.5) * dk.xy, g11 = dk.yy;
  // k g
  const T kg00 = k.xx * g00 + k.xy * g01, kg01 = k.xx * g01 + k.xy * g11;
  const T kg10 = k.xy * g00 + k.yy * g01, kg11 = k.xy * g01 + k.yy * g11;
  // -(k g) k, off-diagonal counted twice for the shared parameter
  return {-(kg00 * k.xx + kg01 * k.xy), -T(2) * (kg00 * k.xy + kg01 * k.yy),
          -(kg10 * k.xy + kg11 * k.yy)};
}

// Rotation matrix of the unit quaternion (w, x, y, z).
template <typename T>
IESRGS_HD Mat3T<T> unit_quat_to_rotation(T w, T x, T y, T z) {
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
           {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
           {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

// Rotation matrix of the quaternion (w, x, y, z), normalized first.
template <typename T>
IESRGS_HD Mat3T<T> quat_to_rotation(const T* q) {
  const T inv = T(1) / hd::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  return unit_quat_to_rotation(q[0] * inv, q[1] * inv, q[2] * inv, q[3] * inv);
}

// Gradient of the unnormalized quaternion from the gradient of quat_to_rotation(q).
template <typename T>
IESRGS_HD void quat_to_rotation_backward(const T* q, const Mat3T<T>& dr, T* dq) {
  const T inv = T(1) / hd::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const T w = q[0] * inv, x = q[1] * inv, y = q[2] * inv, z = q[3] * inv;
  const auto& g = dr.m;
  const T dn[4] = {
      2 * (-z * g[0][1] + y * g[0][2] + z * g[1][0] - x * g[1][2] - y * g[2][0] + x * g[2][1]),
      2 * (y * g[0][1] + z * g[0][2] + y * g[1][0] - 2 * x * g[1][1] - w * g[1][2] + z * g[2][0] +
           w * g[2][1] - 2 * x * g[2][2]),
      2 * (-2 * y * g[0][0] + x * g[0][1] + w * g[0][2] + x * g[1][0] + z * g[1][2] - w * g[2][0] +
           z * g[2][1] - 2 * y * g[2][2]),
      2 * (-2 * z * g[0][0] - w * g[0][1] + x * g[0][2] + w * g[1][0] - 2 * z * g[1][1] +
           y * g[1][2] + x * g[2][0] + y * g[2][1])};
  // Through the normalization: the radial part of the gradient vanishes.
  const T radial = w * dn[0] + x * dn[1] + y * dn[2] + z * dn[3];
  const T n[4] = {w, x, y, z};
  for (int i = 0; i < 4; ++i) dq[i] = (dn[i] - n[i] * radial) * inv;
}

}  // namespace iesrgs
