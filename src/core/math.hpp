#pragma once
// Small fixed-size vector and matrix types for camera geometry (double precision on the host),
// and the scalar helpers around them (sigmoid and logit, median, evenly spaced picks, ...).
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace iesrgs {

inline constexpr double kPi = 3.14159265358979323846;
// The degree-0 real spherical harmonic, 1 / (2 sqrt(pi)): splat colour = 0.5 + kShC0 * f_dc.
inline constexpr double kShC0 = 0.28209479177387814;

struct Vec3 {
  double x = 0, y = 0, z = 0;

  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
  Vec3 operator-() const { return {-x, -y, -z}; }
  double dot(const Vec3& o) const { return x * o.x + y * o.y + z * o.z; }
  Vec3 cross(const Vec3& o) const {
    return {y * o.z - z * o.y, z * o.x - x * o.z, x * o.y - y * o.x};
  }
  double norm() const { return std::sqrt(dot(*this)); }
};

// -1, 0 or 1: the derivative of |t| as torch takes it, 0 at t = 0.
template <typename T>
T sign(T t) {
  return T((t > 0) - (t < 0));
}

// Whether a value read in double precision survives the float conversion that training applies to
// positions and intrinsics: false for NaN, infinities and magnitudes beyond float's range.
inline bool fits_float(double value) {
  return std::abs(value) <= std::numeric_limits<float>::max();
}

inline double sigmoid(double x) {
  return 1 / (1 + std::exp(-x));
}

inline double logit(double p) {
  return std::log(p / (1 - p));
}

inline Vec3 normalized(const Vec3& v) {
  return v * (1 / v.norm());
}

// Row-major 3x3 matrix.
struct Mat3 {
  std::array<double, 9> m{1, 0, 0, 0, 1, 0, 0, 0, 1};

  double operator()(int r, int c) const { return m[r * 3 + c]; }
  double& operator()(int r, int c) { return m[r * 3 + c]; }

  Vec3 operator*(const Vec3& v) const {
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
            m[6] * v.x + m[7] * v.y + m[8] * v.z};
  }
  Mat3 operator*(const Mat3& o) const {
    Mat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r(i, j) = (*this)(i, 0) * o(0, j) + (*this)(i, 1) * o(1, j) + (*this)(i, 2) * o(2, j);
    return r;
  }
  double determinant() const {
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
  }
  Mat3 transposed() const {
    Mat3 r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(i, j) = (*this)(j, i);
    return r;
  }
};

// x with a * x = b, by Cramer's rule; the caller checks that `a` is well conditioned.
Vec3 solve(const Mat3& a, const Vec3& b);

// The middle value (the upper one of the two middle values for an even count); 0 when empty.
double median(std::vector<double> values);

// The indices of `count` of `total` items (all of them when count is larger), spread evenly from
// the first: i * total / count.
std::vector<size_t> evenly_spaced(size_t total, size_t count);

// Rotation matrix of the quaternion (w, x, y, z), normalized first as COLMAP does on read; the
// caller checks that it has a length.
Mat3 quat_to_rotation(double w, double x, double y, double z);

// Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method, numerically stable).
std::array<double, 4> rotation_to_quat(const Mat3& r);

}  // namespace iesrgs
