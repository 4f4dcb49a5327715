#include <gtest/gtest.h>

#include <cmath>

#include "synth/renderer.hpp"

namespace iesrgs::synth {
namespace {

constexpr double kDistance = 4;  // from the camera to the test sphere's center
constexpr double kRadius = 0.5;

// Flat grey: glyphs with ink equal to paper have no pattern, so shading shows alone.
Texture grey() {
  Texture texture;
  texture.pattern = Pattern::Glyphs;
  texture.paper = texture.ink = {0.5, 0.5, 0.5};
  return texture;
}

// One sphere at the origin, seen from +x; the light comes from `light`.
SynthScene sphere_scene(const Vec3& light) {
  SynthScene scene;
  scene.objects.push_back({Sphere{{0, 0, 0}, kRadius}, grey()});
  scene.light_direction = normalized(light);
  return scene;
}

const CameraPose kFront = look_at({kDistance, 0, 0}, {0, 0, 0});

RenderSettings settings(int size) {
  RenderSettings s;
  s.width = s.height = size;
  return s;
}

// Depth along the optical axis of the ray through the center of pixel `x` of row `y`, where
// that ray makes the angle `theta` with the axis.
double sphere_depth(double theta) {
  const double along = kDistance * std::cos(theta);
  const double half_chord = std::sqrt(kRadius * kRadius - std::pow(kDistance * std::sin(theta), 2));
  return (along - half_chord) * std::cos(theta);
}

TEST(SynthRenderer, AlphaIsCoverageAndColourIsNotPremultiplied) {
  // Lit from behind, the visible half is ambient only: one flat colour, whatever the coverage.
  const SynthScene scene = sphere_scene({-1, 0, 0});
  const float flat = float(0.5 * scene.ambient);
  const RenderedView view = render_view(scene, kFront, settings(33));
  EXPECT_EQ(view.rgba.at(16, 16, 3), 1.f);
  for (int corner : {0, 32}) {
    EXPECT_EQ(view.rgba.at(corner, corner, 3), 0.f);
    EXPECT_EQ(view.rgba.at(corner, 32 - corner, 3), 0.f);
    EXPECT_EQ(view.depth[corner * 33 + corner], 0.f);
    EXPECT_EQ(view.rgba.at(corner, corner, 0), 0.f);
  }
  int partial = 0;
  for (size_t i = 0; i < view.rgba.pixels(); ++i) {
    const float alpha = view.rgba.data[i * 4 + 3];
    partial += alpha > 0 && alpha < 1;
    EXPECT_EQ(alpha > 0, view.depth[i] > 0);
    EXPECT_NEAR(view.rgba.data[i * 4], alpha > 0 ? flat : 0.f, 1e-6);
  }
  EXPECT_GT(partial, 8);  // the silhouette is antialiased
}

TEST(SynthRenderer, DepthIsTheAnalyticDistanceAlongTheAxis) {
  const int size = 65;  // odd, so the middle pixel is centered on the optical axis
  const RenderedView view = render_view(sphere_scene({1, 0, 0}), kFront, settings(size));
  const double focal = 0.5 * size / std::tan(0.5 * kCameraAngleX);
  // Samples spread over the pixel see a slightly curved surface: allow for that.
  EXPECT_NEAR(view.depth[32 * size + 32], kDistance - kRadius, 1e-3);
  const int x = 32 + 6;
  EXPECT_NEAR(view.depth[32 * size + x], sphere_depth(std::atan(6 / focal)), 1e-3);
  EXPECT_GT(view.depth[32 * size + x], view.depth[32 * size + 32]);
}

TEST(SynthRenderer, LambertianWithAmbient) {
  const int center = 16;
  const auto lit = [&](const Vec3& light) {
    return render_view(sphere_scene(light), kFront, settings(33)).rgba.at(center, center, 0);
  };
  const double ambient = SynthScene{}.ambient;
  // The center pixel's normal points at the camera, along +x.
  EXPECT_NEAR(lit({1, 0, 0}), 0.5, 1e-3);
  EXPECT_NEAR(lit({1, 0, 1}), 0.5 * (ambient + (1 - ambient) * std::sqrt(0.5)), 2e-3);
  EXPECT_NEAR(lit({-1, 0, 0}), 0.5 * ambient, 1e-6);  // light from behind
}

TEST(SynthRenderer, ObjectsCastShadows) {
  SynthScene scene = sphere_scene({1, 0, 1});
  // A small ball between the front of the sphere and the light, out of the camera's center ray.
  scene.objects.push_back({Sphere{{kRadius + 0.7, 0, 0.7}, 0.2}, grey()});
  const RenderedView view = render_view(scene, kFront, settings(33));
  EXPECT_NEAR(view.rgba.at(16, 16, 0), 0.5 * scene.ambient, 1e-6);
}

}  // namespace
}  // namespace iesrgs::synth
