#include "synth/texture.hpp"

#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>

#include "synth/random.hpp"

namespace iesrgs::synth {

namespace {

Vec3 mix(const Vec3& a, const Vec3& b, double t) {
  return a * (1 - t) + b * t;
}

int64_t cell_of(double x, double size) {
  return int64_t(std::floor(x / size));
}

int64_t floor_div(int64_t a, int64_t b) {
  return a / b - (a % b != 0 && (a < 0) != (b < 0));
}

// 1 on the odd squares of a checkerboard with squares of `size`, else 0.
double checker_parity(double u, double v, double size) {
  return double((cell_of(u, size) + cell_of(v, size)) & 1);
}

Vec3 checker(const Texture& t, double u, double v) {
  const double coarse = checker_parity(u, v, t.scale);
  const double medium = checker_parity(u, v, t.scale / 4);
  const double fine = checker_parity(u, v, t.scale / 16);
  return mix(t.paper, t.ink, coarse) * (0.72 + 0.18 * medium + 0.1 * fine);
}

Vec3 stripes(const Texture& t, double u, double v) {
  const double c = std::cos(t.angle), s = std::sin(t.angle);
  const double along = u * c + v * s;
  const double across = -u * s + v * c;
  const double row_position = across / t.scale - std::floor(across / t.scale);
  if (row_position < 0.1) return t.paper * 0.6;  // a thin groove between rows
  const uint64_t bar = hash_cell(cell_of(along, t.scale / 12), cell_of(across, t.scale), t.seed);
  return unit_interval(bar) < 0.45 ? t.ink : t.paper;
}

// Pseudo-characters are drawn on a 5x7 dot grid from up to nine straight strokes, like a
// segment display; a character cell is 6 dots wide and a text line 9 dots tall.
constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kCellWidth = 6, kLineHeight = 9;

struct Stroke {
  int x0, x1, y0, y1;  // inclusive dot ranges
};

constexpr std::array<Stroke, 9> kStrokes{{
    {0, 4, 0, 0},  // top bar
    {0, 4, 3, 3},  // middle bar
    {0, 4, 6, 6},  // bottom bar
    {0, 0, 0, 3},  // upper left
    {0, 0, 3, 6},  // lower left
    {4, 4, 0, 3},  // upper right
    {4, 4, 3, 6},  // lower right
    {2, 2, 0, 3},  // upper stem
    {2, 2, 3, 6},  // lower stem
}};

// Which strokes a character uses; every sixth cell is a space between words.
unsigned glyph_strokes(uint64_t bits) {
  if ((bits >> 32) % 6 == 0) return 0;
  unsigned strokes = unsigned(bits) & ((1u << kStrokes.size()) - 1);
  if (std::bitset<kStrokes.size()>(strokes).count() < 3) strokes |= 0b11000;  // a full left bar
  return strokes;
}

bool glyph_dot(unsigned strokes, int x, int y) {
  for (size_t i = 0; i < kStrokes.size(); ++i) {
    const Stroke& s = kStrokes[i];
    if ((strokes >> i & 1) && x >= s.x0 && x <= s.x1 && y >= s.y0 && y <= s.y1) return true;
  }
  return false;
}

Vec3 glyphs(const Texture& t, double u, double v) {
  const double dot = t.scale / kLineHeight;
  const int64_t dot_x = cell_of(u, dot), dot_y = cell_of(v, dot);
  const int64_t column = floor_div(dot_x, kCellWidth), line = floor_div(dot_y, kLineHeight);
  const int x = int(dot_x - column * kCellWidth), y = int(dot_y - line * kLineHeight);
  if (x >= kGlyphWidth || y >= kGlyphHeight) return t.paper;
  const unsigned strokes = glyph_strokes(hash_cell(column, line, t.seed));
  return glyph_dot(strokes, x, y) ? t.ink : t.paper;
}

double smoothstep(double x) {
  return x * x * (3 - 2 * x);
}

// Value noise in [0, 1): random values on the integer lattice, smoothly interpolated.
double value_noise(double x, double y, uint64_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int64_t ix = int64_t(fx), iy = int64_t(fy);
  const double sx = smoothstep(x - fx), sy = smoothstep(y - fy);
  auto lattice = [&](int64_t dx, int64_t dy) {
    return unit_interval(hash_cell(ix + dx, iy + dy, seed));
  };
  const double bottom = lattice(0, 0) + (lattice(1, 0) - lattice(0, 0)) * sx;
  const double top = lattice(0, 1) + (lattice(1, 1) - lattice(0, 1)) * sx;
  return bottom + (top - bottom) * sy;
}

Vec3 noise(const Texture& t, double u, double v) {
  constexpr int kOctaves = 5;  // the finest is 1/16 of the scale
  double sum = 0, amplitude = 0.5, frequency = 1 / t.scale;
  for (int octave = 0; octave < kOctaves; ++octave) {
    sum += amplitude * value_noise(u * frequency, v * frequency, t.seed + octave);
    amplitude *= 0.5;
    frequency *= 2;
  }
  // The octaves' sum clusters around 0.5; stretch it so both colours really appear.
  return mix(t.paper, t.ink, std::clamp((sum - 0.5) * 3 + 0.5, 0.0, 1.0));
}

}  // namespace

Vec3 texture_color(const Texture& texture, double u, double v) {
  switch (texture.pattern) {
    case Pattern::Checker:
      return checker(texture, u, v);
    case Pattern::Stripes:
      return stripes(texture, u, v);
    case Pattern::Glyphs:
      return glyphs(texture, u, v);
    case Pattern::Noise:
      return noise(texture, u, v);
  }
  return texture.paper;
}

}  // namespace iesrgs::synth
