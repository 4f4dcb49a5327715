#include "io/undistort.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

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

// Moves (x, y) to the normalized undistorted point that `distortion` maps to (xd, yd), by
// Newton's method on Distortion::apply with a numeric Jacobian, starting from (x, y). False when
// it does not converge, or converges where the map has folded back (a non-positive Jacobian):
// no ray through such a point reached the image.
bool invert(const Distortion& distortion, double xd, double yd, double& x, double& y) {
  constexpr double kStep = 1e-7, kTolerance = 1e-10;
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
    if (std::abs(ex) < kTolerance && std::abs(ey) < kTolerance) return det > 0;
    if (!(std::abs(det) > 1e-12)) return false;
    x -= (d * ex - b * ey) / det;
    y -= (a * ey - c * ex) / det;
    if (!std::isfinite(x) || !std::isfinite(y)) return false;
  }
  return false;
}

// Inverts the lens along a path of distorted normalized points, each solve starting from the
// last one's root, so that the roots stay on the branch the lens saw: a polynomial lens has
// other roots beyond its fold, which a solve started far from the axis can land on. Calls
// take(x, y) with each root; false where the inverse breaks off.
template <typename Path, typename Take>
bool follow(const Distortion& distortion, int steps, const Path& path, double& x, double& y,
            const Take& take) {
  for (int i = 1; i <= steps; ++i) {
    const auto [xd, yd] = path(double(i) / steps);
    if (!invert(distortion, xd, yd, x, y)) return false;
    take(x, y);
  }
  return true;
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
  constexpr int kAxisSteps = 32, kSideSteps = 128;  // the rectangle is as tight as their spacing
  using Point = std::pair<double, double>;
  const auto normalized = [&](const Point& pixel) -> Point {
    return {(pixel.first - lens.cx) / lens.fx, (pixel.second - lens.cy) / lens.fy};
  };
  // One side of the frame, frame_point(t) for t in [0, 1] (pixels, corner at 0), undistorted:
  // reached from the optical axis at its middle, then followed to both ends. `take` sees the
  // side's points; those on the way from the axis lie inside the frame and bound nothing.
  const auto side = [&](const auto& frame_point, const auto& take) {
    const Point middle = normalized(frame_point(0.5));
    const auto toward_middle = [&](double t) -> Point {
      return {middle.first * t, middle.second * t};
    };
    double x = 0, y = 0;
    if (!follow(distortion, kAxisSteps, toward_middle, x, y, [](double, double) {})) return false;
    take(x, y);
    for (const double end : {0.0, 1.0}) {
      const auto toward_end = [&](double t) {
        return normalized(frame_point(0.5 + (end - 0.5) * t));
      };
      double ex = x, ey = y;
      if (!follow(distortion, kSideSteps, toward_end, ex, ey, take)) return false;
    }
    return true;
  };
  const double w = lens.width, h = lens.height, inf = std::numeric_limits<double>::infinity();
  const auto left_edge = [&](double t) { return Point{0, t * h}; };
  const auto right_edge = [&](double t) { return Point{w, t * h}; };
  const auto top_edge = [&](double t) { return Point{t * w, 0}; };
  const auto bottom_edge = [&](double t) { return Point{t * w, h}; };
  double left = -inf, right = inf, top = -inf, bottom = inf;
  const bool inverted = side(left_edge, [&](double x, double) { left = std::max(left, x); }) &&
                        side(right_edge, [&](double x, double) { right = std::min(right, x); }) &&
                        side(top_edge, [&](double, double y) { top = std::max(top, y); }) &&
                        side(bottom_edge, [&](double, double y) { bottom = std::min(bottom, y); });
  if (!inverted || !(right > left && bottom > top)) return std::nullopt;
  Intrinsics pinhole = lens;
  pinhole.fx = lens.width / (right - left);
  pinhole.cx = -left * pinhole.fx;
  pinhole.fy = lens.height / (bottom - top);
  pinhole.cy = -top * pinhole.fy;
  return pinhole;
}

}  // namespace iesrgs
