#include "io/undistort.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace iesrgs {

namespace {

// Bilinear sample of every channel at pixel coordinates (x, y), pixel centers at +0.5, clamped to
// the border. fmin / fmax (not std::clamp) also map infinities and NaN into the image.
void sample_bilinear(const Image8& image, double x, double y, uint8_t* out) {
  const double px = std::fmin(std::fmax(x - 0.5, 0.0), image.width - 1.0);
  const double py = std::fmin(std::fmax(y - 0.5, 0.0), image.height - 1.0);
  const int x0 = static_cast<int>(px), y0 = static_cast<int>(py);
  const int x1 = std::min(x0 + 1, image.width - 1), y1 = std::min(y0 + 1, image.height - 1);
  const double wx = px - x0, wy = py - y0;
  for (int c = 0; c < image.channels; ++c) {
    const double top = image.at(x0, y0, c) * (1 - wx) + image.at(x1, y0, c) * wx;
    const double bottom = image.at(x0, y1, c) * (1 - wx) + image.at(x1, y1, c) * wx;
    out[c] = static_cast<uint8_t>(std::lround(top * (1 - wy) + bottom * wy));
  }
}

// Where the pinhole image's point (u, v) lies in the distorted image (image corner at 0).
void source_point(const Intrinsics& k, const Distortion& distortion, double u, double v, double& x,
                  double& y) {
  double xd, yd;
  distortion.apply((u - k.cx) / k.fx, (v - k.cy) / k.fy, xd, yd);
  x = xd * k.fx + k.cx;
  y = yd * k.fy + k.cy;
}

}  // namespace

double share_sampled_outside(const Intrinsics& intrinsics, const Distortion& distortion) {
  // The centers of a grid's cells, evenly over the frame: a share, not every pixel, is asked for.
  constexpr int kGrid = 128;
  const int columns = std::min(kGrid, intrinsics.width), rows = std::min(kGrid, intrinsics.height);
  int64_t outside = 0;
  for (int row = 0; row < rows; ++row)
    for (int column = 0; column < columns; ++column) {
      const double u = (column + 0.5) * intrinsics.width / columns;
      const double v = (row + 0.5) * intrinsics.height / rows;
      double x, y;
      source_point(intrinsics, distortion, u, v, x, y);
      outside += !(x >= 0 && x <= intrinsics.width && y >= 0 && y <= intrinsics.height);
    }
  return double(outside) / (double(columns) * rows);
}

Image8 undistort_image(const Image8& image, const Intrinsics& intrinsics,
                       const Distortion& distortion) {
  Image8 out(image.width, image.height, image.channels);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < image.height; ++v)
    for (int u = 0; u < image.width; ++u) {
      double x, y;
      source_point(intrinsics, distortion, u + 0.5, v + 0.5, x, y);
      sample_bilinear(image, x, y, &out.at(u, v, 0));
    }
  return out;
}

}  // namespace iesrgs
