#pragma once
// A reproducible random scene for benchmarking the rasterizer, shaped like a trained 3DGS object
// scene seen by a NeRF-Synthetic-like camera: Gaussians in the view frustum at depth 2.5..5.5,
// log-normal sizes (median about 1.2 px standard deviation on screen, a long tail of large ones),
// spread-out opacities, degree-3 SH, and Mip-Splatting 3D filters for this camera.
#include <cstdint>

#include "raster/types.hpp"

namespace iesrgs::raster {

using GaussianCloud = GaussianBuffers<float>;

// Camera at the origin looking down +z with NeRF Synthetic's field of view (about 40 degrees).
RasterCamera<float> benchmark_camera(int width, int height);

GaussianCloud synthetic_scene(int count, const RasterCamera<float>& camera, uint32_t seed);

}  // namespace iesrgs::raster
