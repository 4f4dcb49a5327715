#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/image.hpp"
#include "io/resize.hpp"

// The fixtures are Pillow 9.4's Image.resize(size, Image.BICUBIC) outputs, written by
// tests/data/make_resize_fixtures.py.

namespace iesrgs {
namespace {

namespace fs = std::filesystem;

const fs::path kFixtures = fs::path(IESRGS_TEST_DATA) / "resize";

struct ResizeFixture {
  fs::path source, expected;
  int width = 0, height = 0;
};

// "<source stem>_to_<w>x<h>.png" is Pillow's resize of "<source stem>.png" to w x h.
std::vector<ResizeFixture> synthetic_fixtures() {
  std::vector<ResizeFixture> fixtures;
  for (const auto& entry : fs::directory_iterator(kFixtures)) {
    const std::string file = entry.path().filename().string();
    const size_t to = file.find("_to_");
    if (to == std::string::npos) continue;  // a source image
    const std::string stem = file.substr(0, to);
    ResizeFixture f;
    if (stem == "lego_r_0" ||
        std::sscanf(file.c_str() + to, "_to_%dx%d.png", &f.width, &f.height) != 2)
      continue;
    f.source = kFixtures / (stem + ".png");
    f.expected = entry.path();
    fixtures.push_back(f);
  }
  std::sort(fixtures.begin(), fixtures.end(),
            [](const ResizeFixture& a, const ResizeFixture& b) { return a.expected < b.expected; });
  return fixtures;
}

int max_abs_difference(const Image8& a, const Image8& b) {
  int worst = 0;
  for (size_t i = 0; i < a.data.size(); ++i)
    worst = std::max(worst, std::abs(a.data[i] - b.data[i]));
  return worst;
}

// Checks the shape and returns the largest per-sample difference.
int compare(const Image8& ours, const Image8& pillow) {
  EXPECT_EQ(ours.width, pillow.width);
  EXPECT_EQ(ours.height, pillow.height);
  EXPECT_EQ(ours.channels, pillow.channels);
  if (ours.data.size() != pillow.data.size()) return 256;
  return max_abs_difference(ours, pillow);
}

TEST(Resize, MatchesPillowOnEveryFixture) {
  const std::vector<ResizeFixture> fixtures = synthetic_fixtures();
  ASSERT_EQ(fixtures.size(), 56u) << "expected 4 modes x 14 resizes in " << kFixtures;
  std::map<int, int> worst_by_channels;
  for (const ResizeFixture& f : fixtures) {
    SCOPED_TRACE(f.expected.filename().string());
    const Image8 ours = resize_bicubic(read_image8(f.source), f.width, f.height);
    const int difference = compare(ours, read_image8(f.expected));
    EXPECT_LE(difference, 1);
    int& worst = worst_by_channels[ours.channels];
    worst = std::max(worst, difference);
  }
  for (const auto& [channels, worst] : worst_by_channels)
    std::cout << "[          ] " << channels << " channels: max abs difference " << worst << "\n";
}

TEST(Resize, MatchesPillowOnLego) {
  const fs::path source = fs::path(IESRGS_SHARED_DATA) / "nerf_synthetic/lego/test/r_0.png";
  if (!fs::exists(source)) GTEST_SKIP() << source << " not found: shared data absent";
  const Image8 lego = read_image8(source);
  for (const int size : {200, 100}) {
    const std::string name = "lego_r_0_to_" + std::to_string(size) + "x" + std::to_string(size);
    SCOPED_TRACE(name);
    const int difference =
        compare(resize_bicubic(lego, size, size), read_image8(kFixtures / (name + ".png")));
    EXPECT_LE(difference, 1);
    std::cout << "[          ] " << name << ": max abs difference " << difference << "\n";
  }
}

// Smooth content keeps the 8-bit intermediate inside [0, 255]: where the first pass overshoots,
// PIL clips it and the float variant, rightly, does not.
Image8 smooth_rgb(int width, int height) {
  Image8 image(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) =
            uint8_t(std::lround(128 + 90 * std::sin(0.31 * x + c) * std::cos(0.23 * y - c)));
  return image;
}

TEST(Resize, FloatAgreesWithEightBitOnRgb) {
  const Image8 source = smooth_rgb(64, 48);
  for (const auto& [w, h] :
       std::vector<std::pair<int, int>>{{32, 24}, {8, 6}, {27, 35}, {256, 192}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const Image8 via_float = to_8bit(resize_bicubic(to_float(source), w, h));
    EXPECT_LE(compare(via_float, resize_bicubic(source, w, h)), 1);
  }
}

TEST(Resize, SameSizeKeepsEveryPixel) {
  // RGBA with fully transparent colored pixels, which a premultiplied round trip would lose.
  const Image8 source = read_image8(kFixtures / "RGBA_37x29.png");
  EXPECT_EQ(resize_bicubic(source, source.width, source.height).data, source.data);
  const Image as_float = to_float(source);
  EXPECT_EQ(resize_bicubic(as_float, source.width, source.height).data, as_float.data);
}

TEST(Resize, RejectsInvalidSizes) {
  const Image8 image(4, 3, 3);
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{0, 3}, {4, 0}, {-2, 3}, {4, -1}}) {
    EXPECT_THROW(resize_bicubic(image, w, h), Error);
    EXPECT_THROW(resize_bicubic(to_float(image), w, h), Error);
  }
  EXPECT_THROW(resize_bicubic(Image8(4, 3, 5), 2, 2), Error);
  EXPECT_THROW(resize_bicubic(Image8(), 2, 2), Error);
}

}  // namespace
}  // namespace iesrgs
