#pragma once
// The analytic shapes of the synthetic scene and their exact ray intersections.
#include <optional>
#include <variant>

#include "core/math.hpp"

namespace iesrgs::synth {

struct Ray {
  Vec3 origin;
  Vec3 direction;  // unit length, so hit distances are Euclidean
};

struct Sphere {
  Vec3 center;
  double radius = 1;
};

// A box with half-extents `half` along its own axes; `to_local` rotates world vectors into the
// box frame (identity for an axis-aligned box).
struct Box {
  Vec3 center;
  Vec3 half{1, 1, 1};
  Mat3 to_local;
};

using Shape = std::variant<Sphere, Box>;

// Where a ray met a surface: the outward unit normal and 2D texture coordinates in world units,
// so a pattern has the same physical scale on every object.
struct SurfacePoint {
  Vec3 normal;
  double u = 0, v = 0;
};

// Distance along the ray to the first surface crossing in front of its origin (the exit when
// the origin is inside), or nothing when the ray misses.
std::optional<double> hit_distance(const Shape& shape, const Ray& ray);

// Normal and texture coordinates at a point on the shape's surface.
SurfacePoint surface_at(const Shape& shape, const Vec3& point);

// A sphere enclosing the shape, for cheap rejection of rays that miss it.
Sphere bounding_sphere(const Shape& shape);

// Rotation about the world z axis (up in the Blender convention) by `angle` radians.
Mat3 rotation_z(double angle);

}  // namespace iesrgs::synth
