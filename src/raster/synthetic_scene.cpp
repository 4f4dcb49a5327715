#include "raster/synthetic_scene.hpp"

#include <cmath>
#include <random>

#include "gs/mip_filter.hpp"
#include "gs/sh.hpp"

namespace iesrgs::raster {

RasterCamera<float> benchmark_camera(int width, int height) {
  RasterCamera<float> cam;
  cam.width = width;
  cam.height = height;
  cam.fx = cam.fy = 1.389f * float(width);  // 1111 px at 800 px, as NeRF Synthetic
  cam.cx = 0.5f * float(width);
  cam.cy = 0.5f * float(height);
  return cam;
}

GaussianCloud synthetic_scene(int count, const RasterCamera<float>& cam, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0, 1);
  std::normal_distribution<float> normal(0, 1);
  GaussianCloud c;
  const size_t n = size_t(count);
  c.means.reserve(3 * n);
  c.log_scales.reserve(3 * n);
  c.quats.reserve(4 * n);
  c.opacity_logits.reserve(n);
  c.sh_dc.reserve(3 * n);
  c.sh_rest.reserve(gs::kShRestFloats * n);
  c.filter_std.reserve(n);
  // Median screen std 1.2 px at the middle depth.
  const float median_scale = 1.2f * 4.0f / cam.fx;
  for (int i = 0; i < count; ++i) {
    const float z = 2.5f + 3.0f * unit(rng);
    // 10% beyond each border, as a scene's Gaussians are not all in view.
    const float u = (1.2f * unit(rng) - 0.6f) * float(cam.width) / cam.fx;
    const float v = (1.2f * unit(rng) - 0.6f) * float(cam.height) / cam.fy;
    c.means.insert(c.means.end(), {u * z, v * z, z});
    const float size = std::log(median_scale) + 0.9f * normal(rng);
    for (int k = 0; k < 3; ++k) c.log_scales.push_back(size + 0.4f * normal(rng));
    for (int k = 0; k < 4; ++k) c.quats.push_back(normal(rng));
    c.opacity_logits.push_back(2.5f * normal(rng));
    for (int k = 0; k < gs::kShCoefficients; ++k)
      for (int ch = 0; ch < 3; ++ch)
        (k == 0 ? c.sh_dc : c.sh_rest).push_back((k == 0 ? 0.8f : 0.05f) * normal(rng));
    c.filter_std.push_back(float(gs::filter3d_std_at(z, cam.fx)));  // for this one camera
  }
  return c;
}

}  // namespace iesrgs::raster
