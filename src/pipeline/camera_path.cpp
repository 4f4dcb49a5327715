#include "pipeline/camera_path.hpp"

#include <fmt/core.h>
#include <torch/torch.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace iesrgs::pipeline {

namespace {

// Cameras that leave this much of the turn around their focus point uncovered get a sweep along
// the arc they cover instead of the whole ellipse, which would look at the scene from behind.
constexpr double kLargestGapForAFullTurn = kPi / 2;

// How much less spread of the cameras' right axes the direction taken for up must have than any
// other (the ratio of the second moments).
constexpr double kClearlyLeastSpread = 0.1;

// Where the training cameras stand around their focus point: the world's up direction, the ellipse
// fitted to their positions in the plane across it, and their mean height.
struct Ring {
  Vec3 focus, up, major, minor;
  double radius_major = 0, radius_minor = 0, mean_radius = 0, height = 0;
  std::vector<double> angles;  // of each camera around `up`, from `major` towards `minor`
};

// People hold cameras level, so the world's up is the direction most nearly perpendicular to
// every camera's right axis (the mean image up tilts towards what cameras look down at). That
// direction is only known when it is clearly the least spread of the right axes: on a narrow arc
// the right axes are nearly parallel, and a little roll makes the two smaller spreads alike and
// its direction noise. Then the mean image up, made perpendicular to the mean right axis, is used.
Vec3 up_direction(const std::vector<const Camera*>& cameras) {
  Vec3 mean_up;
  torch::Tensor moments = torch::zeros({3, 3}, torch::kFloat64);
  auto m = moments.accessor<double, 2>();
  for (const Camera* camera : cameras) {
    mean_up = mean_up - camera->axis(1);
    const Vec3 right = camera->axis(0);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m[i][j] += right[i] * right[j];
  }
  mean_up = normalized(mean_up);
  const auto [values, vectors] = torch::linalg_eigh(moments, "L");  // ascending
  const auto v = vectors.accessor<double, 2>();
  const double least = values[0].item<double>(), second = values[1].item<double>();
  // Right axes parallel to rounding leave both at eigensolver noise.
  if (second > 1e-9 * double(cameras.size()) && least < kClearlyLeastSpread * second) {
    const Vec3 up{v[0][0], v[1][0], v[2][0]};
    return up.dot(mean_up) < 0 ? -up : up;
  }
  const Vec3 right{v[0][2], v[1][2], v[2][2]};
  return normalized(mean_up - right * mean_up.dot(right));
}

Ring fit_ring(const std::vector<const Camera*>& cameras) {
  Ring ring;
  const std::optional<Vec3> focus = focus_point(cameras);
  if (!focus)
    fail(
        "the {} training cameras look in parallel directions: no point to circle around (an "
        "interpolated path follows the cameras instead)",
        cameras.size());
  ring.focus = *focus;
  double farthest = 0;
  for (const Camera* camera : cameras)
    farthest = std::max(farthest, (camera->center() - ring.focus).norm());
  if (farthest <= 1e-9 * (1 + ring.focus.norm()))
    fail(
        "the {} training cameras stand at the point they look around, ({:.6g}, {:.6g}, {:.6g}): "
        "no circle to fly (an interpolated path follows the cameras instead)",
        cameras.size(), ring.focus.x, ring.focus.y, ring.focus.z);
  ring.up = up_direction(cameras);
  // Any orthonormal basis of the plane across `up`.
  const Vec3 e1 =
      normalized(ring.up.cross(std::abs(ring.up.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
  const Vec3 e2 = ring.up.cross(e1);
  double sxx = 0, syy = 0, sxy = 0;
  const double n = double(cameras.size());
  for (const Camera* camera : cameras) {
    const Vec3 offset = camera->center() - ring.focus;
    const double x = offset.dot(e1), y = offset.dot(e2);
    sxx += x * x / n;
    syy += y * y / n;
    sxy += x * y / n;
    ring.mean_radius += std::hypot(x, y) / n;
    ring.height += offset.dot(ring.up) / n;
  }
  // Principal axes of the second moments; points spread evenly over an ellipse with semi-axis r
  // have a second moment of r^2 / 2 along it.
  const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);
  const double c = std::cos(angle), s = std::sin(angle);
  ring.major = e1 * c + e2 * s;
  ring.minor = ring.up.cross(ring.major);
  const double along_major = sxx * c * c + syy * s * s + 2 * sxy * s * c;
  ring.radius_major = std::sqrt(2 * std::max(along_major, 0.0));
  ring.radius_minor = std::sqrt(2 * std::max(sxx + syy - along_major, 0.0));
  for (const Camera* camera : cameras) {
    const Vec3 offset = camera->center() - ring.focus;
    ring.angles.push_back(std::atan2(offset.dot(ring.minor), offset.dot(ring.major)));
  }
  std::sort(ring.angles.begin(), ring.angles.end());
  return ring;
}

// The arc the cameras cover: where it starts (just after the largest gap between neighbouring
// cameras) and how far it reaches.
struct Arc {
  double start = 0, span = 0;
};

Arc covered_arc(const std::vector<double>& sorted_angles) {
  double gap = sorted_angles.front() + 2 * kPi - sorted_angles.back();
  double start = sorted_angles.front();
  for (size_t i = 1; i < sorted_angles.size(); ++i) {
    if (sorted_angles[i] - sorted_angles[i - 1] > gap) {
      gap = sorted_angles[i] - sorted_angles[i - 1];
      start = sorted_angles[i];
    }
  }
  return {start, 2 * kPi - gap};
}

// World-to-camera pose of a camera at `eye` looking at `target` with `up` pointing up in the
// image (OpenCV rows: right, down, forward).
void look_at(Camera& camera, const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 forward = normalized(target - eye);
  Vec3 right = forward.cross(up);
  // Looking straight along `up`: any right vector across the view will do.
  if (right.norm() < 1e-9)
    right = forward.cross(std::abs(forward.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0});
  right = normalized(right);
  const Vec3 down = forward.cross(right);
  camera.rotation.m = {right.x, right.y,   right.z,   down.x,   down.y,
                       down.z,  forward.x, forward.y, forward.z};
  camera.translation = -(camera.rotation * eye);
}

// Catmull-Rom between p1 and p2 at t in [0, 1], with p0 and p3 the neighbours on either side: a
// curve through every key position with a continuous tangent.
Vec3 catmull_rom(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, double t) {
  const double t2 = t * t, t3 = t2 * t;
  return (p1 * 2 + (p2 - p0) * t + (p0 * 2 - p1 * 5 + p2 * 4 - p3) * t2 +
          (p1 * 3 - p0 - p2 * 3 + p3) * t3) *
         0.5;
}

// Spherical interpolation of unit quaternions (w, x, y, z), along the shorter arc.
std::array<double, 4> slerp(std::array<double, 4> a, const std::array<double, 4>& b, double t) {
  double cosine = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  if (cosine < 0) {
    for (double& v : a) v = -v;
    cosine = -cosine;
  }
  double wa = 1 - t, wb = t;  // nearly equal rotations: linear is exact enough and stable
  if (cosine < 0.9995) {
    const double angle = std::acos(cosine);
    wa = std::sin((1 - t) * angle) / std::sin(angle);
    wb = std::sin(t * angle) / std::sin(angle);
  }
  std::array<double, 4> q;
  double norm = 0;
  for (int k = 0; k < 4; ++k) {
    q[k] = wa * a[k] + wb * b[k];
    norm += q[k] * q[k];
  }
  for (double& v : q) v /= std::sqrt(norm);
  return q;
}

Camera path_camera(const Camera& intrinsics_from, int index) {
  Camera camera = intrinsics_from;
  camera.name = fmt::format("path_{:04d}", index);
  camera.image_path.clear();
  return camera;
}

}  // namespace

std::vector<Camera> orbit_path(const std::vector<const Camera*>& cameras, int frames) {
  if (cameras.empty()) fail("a camera path needs at least one training camera");
  if (frames < 1) fail("a camera path needs at least one frame, got {}", frames);
  const Ring ring = fit_ring(cameras);
  const Arc arc = covered_arc(ring.angles);
  const bool full_turn = 2 * kPi - arc.span <= kLargestGapForAFullTurn;
  std::vector<Camera> path;
  for (int k = 0; k < frames; ++k) {
    const double phase = 2 * kPi * k / frames;
    Vec3 around;
    if (full_turn) {
      around = ring.major * (ring.radius_major * std::cos(phase)) +
               ring.minor * (ring.radius_minor * std::sin(phase));
    } else {  // out along the arc and back, slowing down at its ends, so the video loops
      const double t = arc.start + arc.span * (1 - std::cos(phase)) / 2;
      around = (ring.major * std::cos(t) + ring.minor * std::sin(t)) * ring.mean_radius;
    }
    Camera camera = path_camera(*cameras.front(), k);
    look_at(camera, ring.focus + around + ring.up * ring.height, ring.focus, ring.up);
    path.push_back(camera);
  }
  return path;
}

std::vector<Camera> interpolated_path(const std::vector<const Camera*>& cameras, int frames) {
  if (cameras.empty()) fail("a camera path needs at least one training camera");
  if (frames < 1) fail("a camera path needs at least one frame, got {}", frames);
  const int last = int(cameras.size()) - 1;
  auto center = [&](int i) { return cameras[std::clamp(i, 0, last)]->center(); };
  std::vector<Camera> path;
  for (int k = 0; k < frames; ++k) {
    // Frame k sits at u along the keys: the first frame on the first camera, the last on the last.
    const double u = frames > 1 ? double(k) * last / (frames - 1) : 0;
    const int i = std::min(int(u), std::max(last - 1, 0));
    const double t = std::min(u - i, 1.0);
    const int next = std::min(i + 1, last);
    const Vec3 eye = catmull_rom(center(i - 1), center(i), center(i + 1), center(i + 2), t);
    const std::array<double, 4> q =
        slerp(rotation_to_quat(cameras[i]->rotation), rotation_to_quat(cameras[next]->rotation), t);
    Camera camera = path_camera(*cameras.front(), k);
    camera.rotation = quat_to_rotation(q[0], q[1], q[2], q[3]);
    camera.translation = -(camera.rotation * eye);
    path.push_back(camera);
  }
  return path;
}

}  // namespace iesrgs::pipeline
