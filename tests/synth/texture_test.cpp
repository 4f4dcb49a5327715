#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "synth/texture.hpp"

namespace iesrgs::synth {
namespace {

double luminance(const Vec3& c) {
  return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

Texture texture_of(Pattern pattern, uint64_t seed = 1) {
  Texture texture;
  texture.pattern = pattern;
  texture.paper = {0.9, 0.8, 0.7};
  texture.ink = {0.1, 0.2, 0.3};
  texture.scale = 0.2;
  texture.angle = 0.4;
  texture.seed = seed;
  return texture;
}

class SynthTexture : public ::testing::TestWithParam<Pattern> {};

// Across a patch of ten pattern scales both colours appear, and neighbours a fiftieth of the
// scale apart differ more than twice as often as features of the coarsest size alone would
// make them (once per 50 steps): there is detail far below the coarsest feature.
TEST_P(SynthTexture, HasContrastAndFineDetail) {
  const Texture texture = texture_of(GetParam());
  const double step = texture.scale / 50;
  double darkest = 1, brightest = 0;
  int changes = 0, pairs = 0;
  for (int i = 0; i < 500; ++i) {
    for (int j = 0; j < 500; j += 7) {
      const double u = i * step - 1, v = j * step + 0.37;
      const double here = luminance(texture_color(texture, u, v));
      const double next = luminance(texture_color(texture, u + step, v));
      darkest = std::min(darkest, here);
      brightest = std::max(brightest, here);
      changes += std::abs(here - next) > 0.02;
      ++pairs;
    }
  }
  const double span = luminance(texture.paper) - luminance(texture.ink);
  EXPECT_GT(brightest - darkest, 0.6 * span);
  EXPECT_GT(double(changes) / pairs, 2.0 / 50);
}

TEST_P(SynthTexture, SeedChangesThePatternDeterministically) {
  const Texture a = texture_of(GetParam(), 1), same = texture_of(GetParam(), 1);
  const Texture other = texture_of(GetParam(), 2);
  int differ = 0;
  for (int i = 0; i < 400; ++i) {
    const double u = 0.0137 * i, v = 0.0291 * i - 3;
    const Vec3 x = texture_color(a, u, v), y = texture_color(same, u, v);
    EXPECT_EQ(x.x, y.x);
    EXPECT_EQ(x.y, y.y);
    EXPECT_EQ(x.z, y.z);
    differ += std::abs(luminance(x) - luminance(texture_color(other, u, v))) > 1e-9;
  }
  if (GetParam() == Pattern::Checker)
    EXPECT_EQ(differ, 0);  // a checkerboard has no randomness
  else
    EXPECT_GT(differ, 40);
}

const char* pattern_name(const ::testing::TestParamInfo<Pattern>& info) {
  constexpr const char* kNames[] = {"Checker", "Stripes", "Glyphs", "Noise"};
  return kNames[int(info.param)];
}

INSTANTIATE_TEST_SUITE_P(Synth, SynthTexture,
                         ::testing::Values(Pattern::Checker, Pattern::Stripes, Pattern::Glyphs,
                                           Pattern::Noise),
                         pattern_name);

}  // namespace
}  // namespace iesrgs::synth
