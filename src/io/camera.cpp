#include "io/camera.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace iesrgs {

const char* split_name(Split split) {
  return split == Split::Train ? "train" : "test";
}

std::string view_name(const std::filesystem::path& image_below_folder) {
  std::string name = std::filesystem::path(image_below_folder).replace_extension().generic_string();
  std::replace(name.begin(), name.end(), '/', '_');
  return name;
}

std::string Distortion::terms_beyond_opencv() const {
  if (!beyond_opencv()) return {};
  return fmt::format("{} {:.9g} {:.9g} {:.9g} {:.9g}", fisheye ? " fisheye" : "", k3, k4, k5, k6);
}

Intrinsics Intrinsics::scaled(double scale) const {
  Intrinsics k = *this;
  k.width = static_cast<int>(std::lround(width * scale));
  k.height = static_cast<int>(std::lround(height * scale));
  // Keep the field of view exact even when the size had to be rounded.
  const double sx = static_cast<double>(k.width) / width;
  const double sy = static_cast<double>(k.height) / height;
  k.fx = fx * sx;
  k.fy = fy * sy;
  k.cx = cx * sx;
  k.cy = cy * sy;
  return k;
}

double Intrinsics::fov_x() const {
  return 2 * std::atan(width / (2 * fx));
}
double Intrinsics::fov_y() const {
  return 2 * std::atan(height / (2 * fy));
}

Camera Camera::scaled(double scale) const {
  Camera c = *this;
  c.intrinsics = intrinsics.scaled(scale);
  return c;
}

std::optional<Vec3> focus_point(const std::vector<const Camera*>& cameras) {
  if (cameras.size() < 2) return std::nullopt;
  // Minimizes sum_i |(I - d_i d_i^T)(p - c_i)|^2 over p: the normal equations below.
  Mat3 a;
  a.m.fill(0);
  Vec3 b;
  for (const Camera* camera : cameras) {
    const Vec3 d = camera->axis(2);
    Mat3 projector;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) projector(i, j) = (i == j) - d[i] * d[j];
    for (int k = 0; k < 9; ++k) a.m[k] += projector.m[k];
    b = b + projector * camera->center();
  }
  if (std::abs(a.determinant()) < 1e-6 * std::pow(double(cameras.size()), 3)) return std::nullopt;
  return solve(a, b);
}

void opengl_c2w_to_opencv_w2c(const double c2w[4][4], Mat3& rotation, Vec3& translation) {
  // Flip the camera's y and z axes (OpenGL -> OpenCV), then invert the rigid transform.
  Mat3 r_c2w;
  for (int i = 0; i < 3; ++i) {
    r_c2w(i, 0) = c2w[i][0];
    r_c2w(i, 1) = -c2w[i][1];
    r_c2w(i, 2) = -c2w[i][2];
  }
  const Vec3 center{c2w[0][3], c2w[1][3], c2w[2][3]};
  rotation = r_c2w.transposed();
  translation = -(rotation * center);
}

}  // namespace iesrgs
