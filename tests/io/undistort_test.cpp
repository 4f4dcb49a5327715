#include "io/undistort.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>

namespace iesrgs {
namespace {

Image8 random_image(int width, int height, int channels) {
  std::mt19937 rng(7);
  Image8 image(width, height, channels);
  for (uint8_t& value : image.data) value = static_cast<uint8_t>(rng() & 255);
  return image;
}

// A smooth pattern over normalized undistorted image coordinates, so it is the same scene for
// the pinhole and the distorted camera.
double pattern(double x, double y) {
  return 127.5 + 100 * std::sin(3 * x + 1) * std::cos(2 * y);
}

// Inverts Distortion::apply by fixed-point iteration (converges for mild distortion).
void undistort_point(const Distortion& d, double xd, double yd, double& x, double& y) {
  x = xd;
  y = yd;
  for (int i = 0; i < 200; ++i) {
    double ax, ay;
    d.apply(x, y, ax, ay);
    x -= ax - xd;
    y -= ay - yd;
  }
  double ax, ay;
  d.apply(x, y, ax, ay);
  ASSERT_NEAR(ax, xd, 1e-12);
  ASSERT_NEAR(ay, yd, 1e-12);
}

// The pattern as seen through `k` and `d`: each pixel shows the scene point whose distorted
// projection falls on its center.
Image8 render_pattern(const Intrinsics& k, const Distortion& d) {
  Image8 image(k.width, k.height, 1);
  for (int v = 0; v < k.height; ++v)
    for (int u = 0; u < k.width; ++u) {
      double x, y;
      undistort_point(d, (u + 0.5 - k.cx) / k.fx, (v + 0.5 - k.cy) / k.fy, x, y);
      image.at(u, v, 0) = static_cast<uint8_t>(std::lround(pattern(x, y)));
    }
  return image;
}

// Whether pixel (u, v) of the pinhole image samples the distorted image at least a pixel inside
// its border (elsewhere the distorted image holds no data and undistortion clamps).
bool sampled_inside(const Intrinsics& k, const Distortion& d, int u, int v) {
  double xd, yd;
  d.apply((u + 0.5 - k.cx) / k.fx, (v + 0.5 - k.cy) / k.fy, xd, yd);
  const double x = xd * k.fx + k.cx, y = yd * k.fy + k.cy;
  return x >= 1 && x <= k.width - 1 && y >= 1 && y <= k.height - 1;
}

TEST(Undistort, DistortedPatternBecomesThePinholePattern) {
  const Intrinsics k{160, 120, 100, 95, 81.3, 58.7};
  for (const Distortion& d : {Distortion{-0.25, 0.05, 0.004, -0.003}, Distortion{0.3, -0.1, 0, 0},
                              Distortion{-0.2, 0.03, 0.002, -0.001, 0.02, 0.1, -0.02, 0.01}}) {
    SCOPED_TRACE(d.k1);
    const Image8 pinhole = render_pattern(k, {});
    const Image8 distorted = render_pattern(k, d);
    const Image8 undistorted = undistort_image(distorted, k, d);
    ASSERT_EQ(undistorted.width, 160);
    ASSERT_EQ(undistorted.height, 120);
    ASSERT_EQ(undistorted.channels, 1);
    int worst_before = 0, worst_after = 0, count = 0;
    double total_after = 0;
    for (int v = 0; v < k.height; ++v)
      for (int u = 0; u < k.width; ++u) {
        if (!sampled_inside(k, d, u, v)) continue;
        const int expected = pinhole.at(u, v, 0);
        worst_before = std::max(worst_before, std::abs(distorted.at(u, v, 0) - expected));
        worst_after = std::max(worst_after, std::abs(undistorted.at(u, v, 0) - expected));
        total_after += std::abs(undistorted.at(u, v, 0) - expected);
        ++count;
      }
    EXPECT_GT(count, k.width * k.height / 2);
    EXPECT_GT(worst_before, 15);  // the distortion is visible, so the comparison means something
    EXPECT_LE(worst_after, 2);
    EXPECT_LT(total_after / count, 0.5);
  }
}

TEST(Undistort, ZeroDistortionIsTheIdentity) {
  const Intrinsics k{37, 23, 30, 31, 18.1, 11.9};
  for (int channels : {1, 3, 4}) {
    const Image8 image = random_image(37, 23, channels);
    const Image8 out = undistort_image(image, k, {});
    EXPECT_EQ(out.channels, channels);
    EXPECT_EQ(out.data, image.data);
  }
}

TEST(Undistort, SamplesOutsideTheImageClampToTheBorder) {
  const Intrinsics k{40, 30, 20, 20, 20, 15};
  const Image8 image = random_image(40, 30, 3);
  // The corners' rays land far outside the distorted image.
  const Image8 out = undistort_image(image, k, {5, 0, 0, 0});
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(out.at(0, 0, c), image.at(0, 0, c));
    EXPECT_EQ(out.at(39, 0, c), image.at(39, 0, c));
    EXPECT_EQ(out.at(39, 29, c), image.at(39, 29, c));
  }
}

// Pincushion pushes the frame's edges beyond the lens's image; barrel pulls the image's edges in.
TEST(Undistort, TheShareSampledOutsideIsWhereTheBorderRepeats) {
  const Intrinsics k{400, 300, 200, 200, 200, 150};
  EXPECT_EQ(share_sampled_outside(k, {}), 0);
  EXPECT_EQ(share_sampled_outside(k, {-0.05, 0, 0, 0}), 0);
  // At the middle of the frame's side (x = 1), the ray lands 1 + k1 = 1.1 out: 20 px beyond.
  const double pincushion = share_sampled_outside(k, {0.1, 0, 0, 0});
  EXPECT_GT(pincushion, 0.02);
  EXPECT_LT(pincushion, 0.2);
  EXPECT_GT(share_sampled_outside(k, {0.5, 0, 0, 0}), pincushion);
}

}  // namespace
}  // namespace iesrgs
