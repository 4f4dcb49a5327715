#pragma once
// The differentiable Gaussian rasterizer on the CPU: 3DGS tile rasterization with Mip-Splatting's
// filters. Forward renders color, alpha and depth; backward turns gradients of those images into
// gradients of every Gaussian parameter. Instantiated for float and double (gradient checks).
#include "io/camera.hpp"
#include "raster/frame.hpp"

namespace iesrgs::raster {

// Caller-owned outputs of the forward pass.
template <typename T>
struct RenderTargets {
  T* image = nullptr;        // (3, H, W) planar RGB, composited over the background
  T* alpha = nullptr;        // (H, W) accumulated opacity
  T* depth = nullptr;        // (H, W) alpha-blended camera z; expected depth = depth / alpha
  int32_t* radii = nullptr;  // (N) screen-space radius in pixels, 0 where not drawn
};

// Gradients of the loss with respect to RenderTargets; any of them may be null (zero).
template <typename T>
struct PixelGrads {
  const T* image = nullptr;
  const T* alpha = nullptr;
  const T* depth = nullptr;
};

template <typename T>
RasterCamera<T> raster_camera(const Camera& camera);

// Renders g seen by cam over background; frame keeps what the backward pass needs.
// Throws Error on invalid sizes or SH degree.
template <typename T>
void rasterize_forward(const GaussianParams<T>& g, const RasterCamera<T>& cam,
                       const T background[3], RasterFrame<T>& frame, const RenderTargets<T>& out);

// Overwrites every array in grads (all must be non-null except the viewspace ones) with the
// gradient of the loss whose pixel gradients are given, for the frame of the latest forward
// call with the same g.
template <typename T>
void rasterize_backward(const GaussianParams<T>& g, RasterFrame<T>& frame,
                        const PixelGrads<T>& pixel_grads, const GaussianGrads<T>& grads);

}  // namespace iesrgs::raster
