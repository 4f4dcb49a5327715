#include "core/math.hpp"

#include <algorithm>

#include "core/geometry.hpp"

namespace iesrgs {

Vec3 solve(const Mat3& a, const Vec3& b) {
  const double det = a.determinant();
  double x[3];
  for (int column = 0; column < 3; ++column) {
    Mat3 replaced = a;
    for (int row = 0; row < 3; ++row) replaced(row, column) = b[row];
    x[column] = replaced.determinant() / det;
  }
  return {x[0], x[1], x[2]};
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

std::vector<size_t> evenly_spaced(size_t total, size_t count) {
  count = std::min(count, total);
  std::vector<size_t> indices(count);
  for (size_t i = 0; i < count; ++i) indices[i] = i * total / count;
  return indices;
}

Mat3 quat_to_rotation(double w, double x, double y, double z) {
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  const Mat3T<double> rotation = unit_quat_to_rotation(w / norm, x / norm, y / norm, z / norm);
  Mat3 r;
  for (int row = 0; row < 3; ++row)
    for (int column = 0; column < 3; ++column) r(row, column) = rotation.m[row][column];
  return r;
}

std::array<double, 4> rotation_to_quat(const Mat3& r) {
  const double trace = r(0, 0) + r(1, 1) + r(2, 2);
  double w, x, y, z;
  if (trace > 0) {
    const double s = 2 * std::sqrt(trace + 1);
    w = s / 4;
    x = (r(2, 1) - r(1, 2)) / s;
    y = (r(0, 2) - r(2, 0)) / s;
    z = (r(1, 0) - r(0, 1)) / s;
  } else if (r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2)) {
    const double s = 2 * std::sqrt(1 + r(0, 0) - r(1, 1) - r(2, 2));
    w = (r(2, 1) - r(1, 2)) / s;
    x = s / 4;
    y = (r(0, 1) + r(1, 0)) / s;
    z = (r(0, 2) + r(2, 0)) / s;
  } else if (r(1, 1) > r(2, 2)) {
    const double s = 2 * std::sqrt(1 + r(1, 1) - r(0, 0) - r(2, 2));
    w = (r(0, 2) - r(2, 0)) / s;
    x = (r(0, 1) + r(1, 0)) / s;
    y = s / 4;
    z = (r(1, 2) + r(2, 1)) / s;
  } else {
    const double s = 2 * std::sqrt(1 + r(2, 2) - r(0, 0) - r(1, 1));
    w = (r(1, 0) - r(0, 1)) / s;
    x = (r(0, 2) + r(2, 0)) / s;
    y = (r(1, 2) + r(2, 1)) / s;
    z = s / 4;
  }
  // A canonical sign keeps written files reproducible.
  if (w < 0) return {-w, -x, -y, -z};
  return {w, x, y, z};
}

}  // namespace iesrgs
