#include "synth/scene_layout.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "synth/random.hpp"

namespace iesrgs::synth {

namespace {

constexpr double kSlabTop = -0.3;
constexpr double kSlabHalfWidth = 0.8;
constexpr double kSlabHalfThickness = 0.06;
// Quadrant objects stand at (+-kQuadrant, +-kQuadrant) +- kJitter with a footprint radius of at
// most 0.28, which keeps them clear of each other, of the tower and of the slab's edge.
constexpr double kQuadrant = 0.44;
constexpr double kJitter = 0.05;

Vec3 hsv_to_rgb(double hue, double saturation, double value) {
  const double h = 6 * (hue - std::floor(hue));
  auto channel = [&](double offset) {
    const double k = std::fmod(offset + h, 6.0);
    return value - value * saturation * std::clamp(std::min(k, 4 - k), 0.0, 1.0);
  };
  return {channel(5), channel(3), channel(1)};
}

// A light "paper" and a dark "ink" colour of contrasting hues.
Texture random_texture(Rng& rng, Pattern pattern, double scale) {
  Texture texture;
  texture.pattern = pattern;
  // Braced lists fix the order of the draws (function arguments would not), for equal scenes
  // from every compiler.
  const double hue = rng.uniform(0, 1);
  const std::array<double, 2> paper{rng.uniform(0.2, 0.55), rng.uniform(0.8, 0.95)};
  const std::array<double, 3> ink{hue + rng.uniform(0.3, 0.7), rng.uniform(0.5, 0.85),
                                  rng.uniform(0.15, 0.4)};
  texture.paper = hsv_to_rgb(hue, paper[0], paper[1]);
  texture.ink = hsv_to_rgb(ink[0], ink[1], ink[2]);
  texture.scale = scale * rng.uniform(0.8, 1.25);
  texture.angle = rng.uniform(0, kPi);
  texture.seed = rng.next();
  return texture;
}

// Each pattern's coarsest feature size, chosen so its finest detail is a few pixels at 800x800.
double pattern_scale(Pattern pattern) {
  switch (pattern) {
    case Pattern::Checker:
      return 0.24;
    case Pattern::Stripes:
      return 0.16;
    case Pattern::Glyphs:
      return 0.09;
    case Pattern::Noise:
      break;
  }
  return 0.2;
}

SceneObject textured(Rng& rng, Shape shape, Pattern pattern) {
  return {std::move(shape), random_texture(rng, pattern, pattern_scale(pattern))};
}

// A box standing on the slab, turned about the vertical by a random angle.
Box standing_box(Rng& rng, double x, double y, const Vec3& half) {
  return {{x, y, kSlabTop + half.z}, half, rotation_z(-rng.uniform(0, kPi))};
}

Sphere resting_sphere(double x, double y, double radius) {
  return {{x, y, kSlabTop + radius}, radius};
}

// Rotation from a random (not uniformly distributed, which does not matter here) quaternion.
Mat3 random_rotation(Rng& rng) {
  std::array<double, 4> q;
  for (double& c : q) c = rng.uniform(-1, 1);
  return quat_to_rotation(q[0], q[1], q[2], q[3]);
}

template <typename T, size_t N>
void shuffle(Rng& rng, std::array<T, N>& items) {
  for (int i = int(N) - 1; i > 0; --i) std::swap(items[i], items[rng.below(i + 1)]);
}

enum class Prop { LargeSphere, SmallSphere, TallCrate, FlatCrate };

Shape make_prop(Rng& rng, Prop prop, double x, double y) {
  switch (prop) {
    case Prop::LargeSphere:
      return resting_sphere(x, y, rng.uniform(0.22, 0.28));
    case Prop::SmallSphere:
      return resting_sphere(x, y, rng.uniform(0.15, 0.21));
    case Prop::TallCrate:
      return standing_box(
          rng, x, y, {rng.uniform(0.12, 0.17), rng.uniform(0.12, 0.17), rng.uniform(0.15, 0.21)});
    case Prop::FlatCrate:
      break;
  }
  return standing_box(rng, x, y,
                      {rng.uniform(0.15, 0.2), rng.uniform(0.15, 0.2), rng.uniform(0.07, 0.1)});
}

// Text-covered, standing on the slab's center and reaching above the origin, so every camera,
// looking at the origin, sees it in the middle of the image.
void add_tower(Rng& rng, SynthScene& scene) {
  const double half_width = rng.uniform(0.1, 0.14);
  const double top = rng.uniform(0.4, 0.6);
  const Vec3 half{half_width, half_width, (top - kSlabTop) / 2};
  scene.objects.push_back(textured(rng, standing_box(rng, 0, 0, half), Pattern::Glyphs));
}

constexpr std::array<std::pair<double, double>, 4> kQuadrants{{{1, 1}, {-1, 1}, {-1, -1}, {1, -1}}};

// One of each prop, each with another pattern, in shuffled quadrants.
void add_quadrant_props(Rng& rng, SynthScene& scene) {
  std::array<Prop, 4> props{Prop::LargeSphere, Prop::SmallSphere, Prop::TallCrate, Prop::FlatCrate};
  std::array<Pattern, 4> patterns{Pattern::Glyphs, Pattern::Stripes, Pattern::Noise,
                                  Pattern::Checker};
  shuffle(rng, props);
  shuffle(rng, patterns);
  for (int i = 0; i < 4; ++i) {
    const double x = kQuadrants[i].first * kQuadrant + rng.uniform(-kJitter, kJitter);
    const double y = kQuadrants[i].second * kQuadrant + rng.uniform(-kJitter, kJitter);
    scene.objects.push_back(textured(rng, make_prop(rng, props[i], x, y), patterns[i]));
  }
}

// High enough above a quadrant to clear whatever stands there, in any orientation.
void add_floating_cube(Rng& rng, SynthScene& scene) {
  const auto& above = kQuadrants[rng.below(4)];
  const Box cube{{above.first * kQuadrant, above.second * kQuadrant, rng.uniform(0.6, 0.75)},
                 Vec3{1, 1, 1} * rng.uniform(0.11, 0.15),
                 random_rotation(rng)};
  scene.objects.push_back(textured(rng, cube, Pattern::Stripes));
}

// Small balls near the middle of each slab edge, between the quadrant props.
void add_edge_spheres(Rng& rng, SynthScene& scene) {
  const std::array<std::pair<double, double>, 4> edges{
      {{0.68, 0}, {0, 0.68}, {-0.68, 0}, {0, -0.68}}};
  for (int i = 0; i < 4; ++i) {
    const double x = edges[i].first + rng.uniform(-0.03, 0.03);
    const double y = edges[i].second + rng.uniform(-0.03, 0.03);
    const Sphere ball = resting_sphere(x, y, rng.uniform(0.05, 0.075));
    scene.objects.push_back(textured(rng, ball, i % 2 ? Pattern::Noise : Pattern::Checker));
  }
}

}  // namespace

SynthScene make_synth_scene(uint64_t seed) {
  Rng rng(seed);
  SynthScene scene;
  scene.light_direction = normalized({0.5, -0.3, 0.8});
  const Box slab{{0, 0, kSlabTop - kSlabHalfThickness},
                 {kSlabHalfWidth, kSlabHalfWidth, kSlabHalfThickness},
                 Mat3{}};
  scene.objects.push_back(textured(rng, slab, Pattern::Checker));
  add_tower(rng, scene);
  add_quadrant_props(rng, scene);
  add_floating_cube(rng, scene);
  add_edge_spheres(rng, scene);
  return scene;
}

}  // namespace iesrgs::synth
