#include "synth/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace iesrgs::synth {

namespace {

// Crossings closer than this are the surface a ray started from (shadow rays leave surfaces).
constexpr double kMinDistance = 1e-9;

// The nearer of the two crossings that lies in front of the origin.
std::optional<double> first_in_front(double t_near, double t_far) {
  if (t_near > kMinDistance) return t_near;
  if (t_far > kMinDistance) return t_far;
  return std::nullopt;
}

// A ray from outside a sphere misses it when it points away or passes too far from the center.
bool misses_sphere(const Vec3& center, double radius2, const Ray& ray) {
  const Vec3 oc = ray.origin - center;
  const double b = oc.dot(ray.direction);
  const double c = oc.dot(oc) - radius2;
  // Bitwise rather than short-circuit: one branch for the caller instead of three.
  return (c > 0) & ((b > 0) | (b * b < c));
}

std::optional<double> hit_sphere(const Sphere& sphere, const Ray& ray) {
  const Vec3 oc = ray.origin - sphere.center;
  const double b = oc.dot(ray.direction);
  const double discriminant = b * b - (oc.dot(oc) - sphere.radius * sphere.radius);
  if (discriminant < 0) return std::nullopt;
  const double root = std::sqrt(discriminant);
  return first_in_front(-b - root, -b + root);
}

// Slab method in the box frame; a direction component of 0 gives infinite slab distances,
// which the min/max handle as "parallel to that pair of faces".
std::optional<double> hit_box(const Box& box, const Ray& ray) {
  // Most rays miss most boxes; the enclosing sphere rejects them without the rotation.
  if (misses_sphere(box.center, box.half.dot(box.half), ray)) return std::nullopt;
  const Vec3 origin = box.to_local * (ray.origin - box.center);
  const Vec3 direction = box.to_local * ray.direction;
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    const double inverse = 1 / direction[axis];
    double t0 = (-box.half[axis] - origin[axis]) * inverse;
    double t1 = (box.half[axis] - origin[axis]) * inverse;
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
  }
  if (t_near > t_far) return std::nullopt;
  return first_in_front(t_near, t_far);
}

SurfacePoint sphere_surface(const Sphere& sphere, const Vec3& point) {
  const Vec3 normal = normalized(point - sphere.center);
  // Longitude and colatitude scaled by the radius: arc lengths, so patterns keep their size.
  const double longitude = std::atan2(normal.y, normal.x);
  const double colatitude = std::acos(std::clamp(normal.z, -1.0, 1.0));
  return {normal, longitude * sphere.radius, colatitude * sphere.radius};
}

SurfacePoint box_surface(const Box& box, const Vec3& point) {
  const Vec3 local = box.to_local * (point - box.center);
  // The face is the axis where the point is relatively farthest out.
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(local[i]) / box.half[i] > std::abs(local[axis]) / box.half[axis]) axis = i;
  const double sign = local[axis] < 0 ? -1 : 1;
  const Vec3 local_normal{axis == 0 ? sign : 0, axis == 1 ? sign : 0, axis == 2 ? sign : 0};
  // Each face gets its own region of texture space, so faces do not repeat each other.
  const double face_offset = 10.0 * (2 * axis + (sign > 0));
  return {box.to_local.transposed() * local_normal, local[(axis + 1) % 3] + face_offset,
          local[(axis + 2) % 3] + face_offset};
}

}  // namespace

std::optional<double> hit_distance(const Shape& shape, const Ray& ray) {
  if (const auto* sphere = std::get_if<Sphere>(&shape)) return hit_sphere(*sphere, ray);
  return hit_box(std::get<Box>(shape), ray);
}

SurfacePoint surface_at(const Shape& shape, const Vec3& point) {
  if (const auto* sphere = std::get_if<Sphere>(&shape)) return sphere_surface(*sphere, point);
  return box_surface(std::get<Box>(shape), point);
}

Sphere bounding_sphere(const Shape& shape) {
  if (const auto* sphere = std::get_if<Sphere>(&shape)) return *sphere;
  const Box& box = std::get<Box>(shape);
  return {box.center, box.half.norm()};
}

Mat3 rotation_z(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Mat3 r;
  r.m = {c, -s, 0, s, c, 0, 0, 0, 1};
  return r;
}

}  // namespace iesrgs::synth
