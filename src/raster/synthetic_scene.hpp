#pragma once
// A reproducible random scene for benchmarking the rasterizer, shaped like a trained 3DGS object
// scene seen by a NeRF-Synthetic-like camera: Gaussians in the view frustum at depth 2.5..5.5,
// log-normal sizes (median about 1.2 px standard deviation on screen, a long tail of large ones),
// spread-out opacities, degree-3 SH, and Mip-Splatting 3D filters for this camera.
#include <cstdint>
#include <vector>

#include "raster/types.hpp"

namespace iesrgs::raster {

struct GaussianCloud {
  int sh_degree = 3;
  std::vector<float> means, log_scales, quats, opacity_logits, sh, filter_std;

  int count() const { return int(opacity_logits.size()); }
  GaussianParams<float> params() const;
};

// Camera at the origin looking down +z with NeRF Synthetic's field of view (about 40 degrees).
RasterCamera<float> benchmark_camera(int width, int height);

GaussianCloud synthetic_scene(int count, const RasterCamera<float>& camera, uint32_t seed);

}  // namespace iesrgs::raster
