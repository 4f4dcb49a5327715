#include "synth/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "synth/random.hpp"

namespace iesrgs::synth {

namespace {

// Shadow rays start this far off the surface so they do not hit it again.
constexpr double kShadowOffset = 1e-6;
constexpr uint64_t kJitterSeed = 0x5eed;

struct Hit {
  const SceneObject* object = nullptr;
  double distance = 0;
};

struct Sample {
  Vec3 color;
  double distance = 0;
};

// A sphere around the origin (where the cameras look) enclosing every object.
Sphere scene_bound(const SynthScene& scene) {
  Sphere bound{{0, 0, 0}, 0};
  for (const SceneObject& object : scene.objects) {
    const Sphere s = bounding_sphere(object.shape);
    bound.radius = std::max(bound.radius, s.center.norm() + s.radius);
  }
  return bound;
}

class Tracer {
 public:
  explicit Tracer(const SynthScene& scene) : scene_(scene), bound_(scene_bound(scene)) {}

  // What the ray sees first, or nothing when it misses every object.
  std::optional<Sample> trace(const Ray& ray) const {
    if (!hit_distance(bound_, ray)) return std::nullopt;
    const std::optional<Hit> hit = nearest_hit(ray);
    if (!hit) return std::nullopt;
    return Sample{shade(ray, *hit), hit->distance};
  }

 private:
  std::optional<Hit> nearest_hit(const Ray& ray) const {
    std::optional<Hit> nearest;
    for (const SceneObject& object : scene_.objects) {
      const std::optional<double> distance = hit_distance(object.shape, ray);
      if (distance && (!nearest || *distance < nearest->distance))
        nearest = Hit{&object, *distance};
    }
    return nearest;
  }

  bool occluded(const Ray& ray) const {
    return std::any_of(scene_.objects.begin(), scene_.objects.end(),
                       [&](const SceneObject& object) { return hit_distance(object.shape, ray); });
  }

  Vec3 shade(const Ray& ray, const Hit& hit) const {
    const Vec3 point = ray.origin + ray.direction * hit.distance;
    const SurfacePoint surface = surface_at(hit.object->shape, point);
    const Vec3 albedo = texture_color(hit.object->texture, surface.u, surface.v);
    const double facing = surface.normal.dot(scene_.light_direction);
    double light = scene_.ambient;
    if (facing > 0 && !occluded({point + surface.normal * kShadowOffset, scene_.light_direction}))
      light += (1 - scene_.ambient) * facing;
    return albedo * light;
  }

  const SynthScene& scene_;
  Shape bound_;
};

struct PixelSampler {
  const Tracer& tracer;
  const CameraPose& pose;
  const RenderSettings& settings;
  double focal;  // pixels

  // Fills pixel (x, y) of the view.
  void render(int x, int y, RenderedView& view) const {
    const int grid = settings.grid;
    const int64_t pixel = int64_t(y) * settings.width + x;
    Vec3 color;
    double depth = 0;
    int hits = 0;
    for (int sample = 0; sample < grid * grid; ++sample) {
      const uint64_t jitter = hash_cell(pixel, sample, kJitterSeed);
      const double px = x + (sample % grid + unit_interval(jitter << 32)) / grid;
      const double py = y + (sample / grid + unit_interval(jitter)) / grid;
      // Camera-space direction with z = -1, so the hit distance over its length is the depth.
      const Vec3 camera{(px - 0.5 * settings.width) / focal, -(py - 0.5 * settings.height) / focal,
                        -1};
      const double length = camera.norm();
      const auto hit = tracer.trace({pose.position, pose.axes * camera * (1 / length)});
      if (!hit) continue;
      color = color + hit->color;
      depth += hit->distance / length;
      ++hits;
    }
    const size_t index = size_t(pixel);
    view.depth[index] = hits ? float(depth / hits) : 0.f;
    for (int c = 0; c < 3; ++c) view.rgba.at(x, y, c) = hits ? float(color[c] / hits) : 0.f;
    view.rgba.at(x, y, 3) = float(hits) / float(grid * grid);
  }
};

}  // namespace

RenderedView render_view(const SynthScene& scene, const CameraPose& pose,
                         const RenderSettings& settings) {
  RenderedView view;
  view.rgba = Image(settings.width, settings.height, 4);
  view.depth.assign(view.rgba.pixels(), 0.f);
  const Tracer tracer(scene);
  const PixelSampler sampler{tracer, pose, settings, settings.focal()};
#pragma omp parallel for schedule(dynamic)
  for (int y = 0; y < settings.height; ++y)
    for (int x = 0; x < settings.width; ++x) sampler.render(x, y, view);
  return view;
}

}  // namespace iesrgs::synth
