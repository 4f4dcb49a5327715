#include "io/camera.hpp"

#include <cmath>

namespace iesrgs {

const char* split_name(Split split) {
  return split == Split::Train ? "train" : "test";
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
