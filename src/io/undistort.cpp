#include "io/undistort.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

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

// The normalized undistorted point that `distortion` maps to (xd, yd): Newton's method on
// Distortion::apply, with a numeric Jacobian. False when it does not converge to a point the lens
// saw: one on the same side of the axis, where the map has not folded back (a polynomial lens's
// other roots lie beyond its fold, and no ray through them reached the image).
bool invert(const Distortion& distortion, double xd, double yd, double& x, double& y) {
  constexpr double kStep = 1e-7, kTolerance = 1e-10;
  x = xd;
  y = yd;
  for (int iteration = 0; iteration < 50; ++iteration) {
    double ex, ey, xx, xy, yx, yy;
    distortion.apply(x, y, ex, ey);
    ex -= xd;
    ey -= yd;
    distortion.apply(x + kStep, y, xx, xy);
    distortion.apply(x, y + kStep, yx, yy);
    const double a = (xx - xd - ex) / kStep, c = (xy - yd - ey) / kStep;  // d/dx
    const double b = (yx - xd - ex) / kStep, d = (yy - yd - ey) / kStep;  // d/dy
    const double det = a * d - b * c;
    if (std::abs(ex) < kTolerance && std::abs(ey) < kTolerance)
      return det > 0 && x * xd + y * yd >= 0;
    if (!(std::abs(det) > 1e-12)) return false;
    x -= (d * ex - b * ey) / det;
    y -= (a * ey - c * ex) / det;
    if (!std::isfinite(x) || !std::isfinite(y)) return false;
  }
  return false;
}

}  // namespace

Image8 undistort_image(const Image8& image, const Intrinsics& lens, const Distortion& distortion,
                       const Intrinsics& pinhole) {
  Image8 out(image.width, image.height, image.channels);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < image.height; ++v)
    for (int u = 0; u < image.width; ++u) {
      double xd, yd;
      distortion.apply((u + 0.5 - pinhole.cx) / pinhole.fx, (v + 0.5 - pinhole.cy) / pinhole.fy, xd,
                       yd);
      sample_bilinear(image, xd * lens.fx + lens.cx, yd * lens.fy + lens.cy, &out.at(u, v, 0));
    }
  return out;
}

std::optional<Intrinsics> pinhole_within_lens(const Intrinsics& lens,
                                              const Distortion& distortion) {
  constexpr int kSamples = 256;  // along each side: the rectangle is as tight as their spacing
  const double inf = std::numeric_limits<double>::infinity();
  double left = -inf, right = inf, top = -inf, bottom = inf;
  double x, y;
  // A point of the frame's edge (pixels, corner at 0), undistorted.
  const auto edge = [&](double px, double py) {
    return invert(distortion, (px - lens.cx) / lens.fx, (py - lens.cy) / lens.fy, x, y);
  };
  for (int i = 0; i <= kSamples; ++i) {
    const double along_x = lens.width * double(i) / kSamples;
    const double along_y = lens.height * double(i) / kSamples;
    if (!edge(0, along_y)) return std::nullopt;
    left = std::max(left, x);
    if (!edge(lens.width, along_y)) return std::nullopt;
    right = std::min(right, x);
    if (!edge(along_x, 0)) return std::nullopt;
    top = std::max(top, y);
    if (!edge(along_x, lens.height)) return std::nullopt;
    bottom = std::min(bottom, y);
  }
  if (!(right > left && bottom > top)) return std::nullopt;
  Intrinsics pinhole = lens;
  pinhole.fx = lens.width / (right - left);
  pinhole.cx = -left * pinhole.fx;
  pinhole.fy = lens.height / (bottom - top);
  pinhole.cy = -top * pinhole.fy;
  return pinhole;
}

}  // namespace iesrgs
