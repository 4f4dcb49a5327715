#pragma once
// The built-in synthetic scene: textured analytic objects on a square slab, inside
// [-1.3, 1.3]^3 like NeRF Synthetic's objects and inside the frame of every orbit view, with z up
// as in Blender.
#include <cstdint>
#include <vector>

#include "synth/geometry.hpp"
#include "synth/texture.hpp"

namespace iesrgs::synth {

struct SceneObject {
  Shape shape;
  Texture texture;
};

struct SynthScene {
  std::vector<SceneObject> objects;
  Vec3 light_direction{0, 0, 1};  // unit vector towards the (infinitely far) light
  double ambient = 0.3;           // share of the albedo seen even where the light does not reach
};

// A slab with a text-covered tower in the middle, four objects around it, a tilted cube
// floating above one of them and four small spheres near the edges. The seed picks sizes,
// positions, rotations, colours and which pattern goes where; the arrangement never overlaps.
SynthScene make_synth_scene(uint64_t seed);

}  // namespace iesrgs::synth
