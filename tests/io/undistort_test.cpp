#include "io/undistort.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <random>
#include <utility>

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
    const Image8 undistorted = undistort_image(distorted, k, d, k);
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

// Into the pinhole within the lens, every pixel shows the pattern as that pinhole sees it.
TEST(Undistort, IntoThePinholeWithinTheLensEveryPixelIsThePinholesView) {
  const Intrinsics k{160, 120, 100, 95, 81.3, 58.7};
  const Distortion fisheye{0.05, 0.01, 0, 0, 0, 0, 0, 0, true};
  for (const Distortion& d :
       {Distortion{-0.25, 0.05, 0.004, -0.003}, Distortion{0.3, -0.1, 0, 0}, fisheye}) {
    SCOPED_TRACE(d.k1);
    const Intrinsics pinhole = pinhole_within_lens(k, d).value();
    ASSERT_GT(std::abs(pinhole.fx - k.fx), 2);  // another camera than the lens's own
    const Image8 expected = render_pattern(pinhole, {});
    const Image8 undistorted = undistort_image(render_pattern(k, d), k, d, pinhole);
    int worst = 0;
    for (size_t i = 0; i < expected.data.size(); ++i)
      worst = std::max(worst, std::abs(undistorted.data[i] - expected.data[i]));
    EXPECT_LE(worst, 3);
  }
}

TEST(Undistort, ZeroDistortionIsTheIdentity) {
  const Intrinsics k{37, 23, 30, 31, 18.1, 11.9};
  for (int channels : {1, 3, 4}) {
    const Image8 image = random_image(37, 23, channels);
    const Image8 out = undistort_image(image, k, {}, k);
    EXPECT_EQ(out.channels, channels);
    EXPECT_EQ(out.data, image.data);
  }
}

TEST(Undistort, SamplesOutsideTheImageClampToTheBorder) {
  const Intrinsics k{40, 30, 20, 20, 20, 15};
  const Image8 image = random_image(40, 30, 3);
  // The corners' rays land far outside the distorted image.
  const Image8 out = undistort_image(image, k, {5, 0, 0, 0}, k);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(out.at(0, 0, c), image.at(0, 0, c));
    EXPECT_EQ(out.at(39, 0, c), image.at(39, 0, c));
    EXPECT_EQ(out.at(39, 29, c), image.at(39, 29, c));
  }
}

// How far inside the lens's frame (pixels; negative: outside) each side of the pinhole's frame
// comes, at its nearest: 0 where the two touch.
std::array<double, 4> margins(const Intrinsics& lens, const Distortion& d,
                              const Intrinsics& pinhole) {
  std::array<double, 4> margin;
  margin.fill(std::numeric_limits<double>::infinity());
  const auto lens_point = [&](double u, double v, double& x, double& y) {
    double xd, yd;
    d.apply((u - pinhole.cx) / pinhole.fx, (v - pinhole.cy) / pinhole.fy, xd, yd);
    x = xd * lens.fx + lens.cx;
    y = yd * lens.fy + lens.cy;
  };
  double x, y;
  for (int i = 0; i <= 1000; ++i) {
    const double u = pinhole.width * i / 1000.0, v = pinhole.height * i / 1000.0;
    lens_point(0, v, x, y);
    margin[0] = std::min(margin[0], x);
    lens_point(pinhole.width, v, x, y);
    margin[1] = std::min(margin[1], lens.width - x);
    lens_point(u, 0, x, y);
    margin[2] = std::min(margin[2], y);
    lens_point(u, pinhole.height, x, y);
    margin[3] = std::min(margin[3], lens.height - y);
  }
  return margin;
}

// As nerfstudio and gsplat undistort (OpenCV's alpha 0): every pixel samples what the lens saw,
// and the frame is no smaller than that needs: a side reaches the lens's edge (the others may
// not, where the point that bounds them falls outside the span of the sides across).
TEST(Undistort, ThePinholeWithinTheLensSeesOnlyWhatTheLensSaw) {
  const Intrinsics lens{400, 300, 200, 210, 205, 148};
  const Intrinsics fox{1080, 1920, 1375.52, 1374.49, 554.558, 965.268};
  const std::pair<Intrinsics, Distortion> cases[] = {
      {lens, {0.1, 0, 0, 0}},
      {lens, {-0.2, 0.03, 0.002, -0.001}},
      {lens, {-0.2, 0.03, 0.002, -0.001, 0.02, 0.1, -0.02, 0.01}},
      {fox, {0.0578421, -0.0805099, -0.000980296, 0.00015575}},
      {lens, {0.05, 0.01, 0, 0, -0.002, 0.0005, 0, 0, true}}};  // a fisheye
  for (const auto& [k, d] : cases) {
    SCOPED_TRACE(d.k1);
    const std::optional<Intrinsics> pinhole = pinhole_within_lens(k, d);
    ASSERT_TRUE(pinhole);
    EXPECT_EQ(pinhole->width, k.width);
    EXPECT_EQ(pinhole->height, k.height);
    const std::array<double, 4> margin = margins(k, d, *pinhole);
    for (double side : margin) EXPECT_GT(side, -0.01);
    EXPECT_LT(*std::min_element(margin.begin(), margin.end()), 0.01);
  }
  // Solved from a distorted corner alone, this wide pincushion lens lands beyond its fold; the
  // inverse followed from the axis finds the point the lens saw.
  const Intrinsics wide{400, 300, 150, 150, 200, 150};
  const Distortion wide_lens{0.351, -0.095, 0.0105, 0.0148};
  const std::optional<Intrinsics> wide_pinhole = pinhole_within_lens(wide, wide_lens);
  ASSERT_TRUE(wide_pinhole);
  for (double side : margins(wide, wide_lens, *wide_pinhole)) EXPECT_GT(side, -0.01);
  // Pincushion leaves the frame's sides beyond the lens's image: the pinhole sees less (longer
  // focal lengths); barrel brings more of the scene into the frame: it sees more.
  EXPECT_GT(pinhole_within_lens(lens, {0.1, 0, 0, 0})->fx, lens.fx);
  EXPECT_LT(pinhole_within_lens(lens, {-0.05, 0, 0, 0})->fx, lens.fx);
  // r (1 - 0.2 r^2) folds back at r = 1.29, short of the frame's corners (1.24 after it): they
  // were not seen through this lens, nor through fox's on this wider frame.
  EXPECT_FALSE(pinhole_within_lens(lens, {-0.2, 0, 0, 0}));
  EXPECT_FALSE(pinhole_within_lens(lens, cases[3].second));
  // The equidistant projection images a ray at 90 degrees at radius pi / 2: a frame reaching past
  // it saw beyond what any pinhole sees.
  const Distortion equidistant{0, 0, 0, 0, 0, 0, 0, 0, true};
  EXPECT_FALSE(pinhole_within_lens({400, 300, 100, 100, 200, 150}, equidistant));
}

}  // namespace
}  // namespace iesrgs
