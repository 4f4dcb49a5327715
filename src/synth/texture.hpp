#pragma once
// Procedural surface patterns with detail at several scales, down to a few pixels at 800x800,
// so a low-resolution view cannot show everything the high-resolution one does.
#include <cstdint>

#include "core/math.hpp"

namespace iesrgs::synth {

enum class Pattern {
  Checker,  // checkers at three frequencies, each modulating the coarser one
  Stripes,  // rows of barcode-like stripes of random widths
  Glyphs,   // lines of small blocky pseudo-characters, like printed text
  Noise,    // fractal value noise
};

struct Texture {
  Pattern pattern = Pattern::Checker;
  Vec3 paper{0.9, 0.9, 0.9};  // background colour, linear [0, 1]
  Vec3 ink{0.1, 0.1, 0.1};    // foreground colour
  double scale = 0.2;         // world size of the coarsest feature (cell, row or line height)
  double angle = 0;           // direction of the stripes in texture space, radians
  uint64_t seed = 0;          // which bars, glyphs and noise
};

// Albedo at texture coordinates (u, v), in world units.
Vec3 texture_color(const Texture& texture, double u, double v);

}  // namespace iesrgs::synth
