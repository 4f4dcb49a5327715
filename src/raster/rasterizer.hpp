#pragma once
// The differentiable Gaussian rasterizer on the CPU: 3DGS tile rasterization with Mip-Splatting's
// filters. Forward renders color, alpha and depth; backward turns gradients of those images into
// gradients of every Gaussian parameter. Instantiated for float and double (gradient checks).
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "gs/sh.hpp"
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

// One array of GaussianGrads and its length; data may be null (not wanted).
template <typename T>
struct GradArray {
  T* data;
  size_t size;
};

// One array of GaussianGrads: its member and its floats per Gaussian.
template <typename T>
struct GradField {
  using Member = T* GaussianGrads<T>::*;
  Member array;
  size_t per_gaussian;
};

// Every array of GaussianGrads, in the order of its members: the one list the helpers below read.
template <typename T>
constexpr std::array<GradField<T>, 8> grad_fields() {
  using G = GaussianGrads<T>;
  return {{{&G::means, 3},
           {&G::log_scales, 3},
           {&G::quats, 4},
           {&G::opacity_logits, 1},
           {&G::sh_dc, 3},
           {&G::sh_rest, gs::kShRestFloats},
           {&G::viewspace, 2},
           {&G::viewspace_abs, 2}}};
}

// Every array of grads for n Gaussians, for the backward passes to clear.
template <typename T>
std::array<GradArray<T>, 8> grad_arrays(const GaussianGrads<T>& grads, size_t n) {
  std::array<GradArray<T>, 8> arrays;
  const auto fields = grad_fields<T>();
  for (size_t k = 0; k < fields.size(); ++k)
    arrays[k] = {grads.*fields[k].array, fields[k].per_gaussian * n};
  return arrays;
}

// Floats that every array of grads for n Gaussians takes, laid end to end (packed_grads).
inline size_t packed_grads_size(size_t n) {
  size_t floats = 0;
  for (const GradField<float>& field : grad_fields<float>()) floats += field.per_gaussian * n;
  return floats;
}

// Every array of grads for n Gaussians in one buffer of packed_grads_size(n) floats at p.
template <typename T>
GaussianGrads<T> packed_grads(T* p, size_t n) {
  GaussianGrads<T> grads;
  for (const GradField<T>& field : grad_fields<T>()) {
    grads.*field.array = p;
    p += field.per_gaussian * n;
  }
  return grads;
}

// Host buffers for one frame of n Gaussians: its render targets and every parameter gradient, for
// the benchmarks that drive the rasterizer directly.
struct HostFrameBuffers {
  std::vector<float> image, alpha, depth, grads;
  std::vector<int32_t> radii;

  HostFrameBuffers(size_t pixels, size_t gaussians)
      : image(3 * pixels),
        alpha(pixels),
        depth(pixels),
        grads(packed_grads_size(gaussians)),
        radii(gaussians) {}
  RenderTargets<float> targets() {
    return {image.data(), alpha.data(), depth.data(), radii.data()};
  }
  GaussianGrads<float> gaussian_grads() { return packed_grads(grads.data(), radii.size()); }
};

// Zeroes the gradients of Gaussians [begin, end) of n.
template <typename T>
void clear_grads(const GaussianGrads<T>& grads, size_t n, size_t begin, size_t end) {
  for (const GradArray<T>& a : grad_arrays(grads, n))
    if (a.data) std::fill(a.data + a.size / n * begin, a.data + a.size / n * end, T(0));
}

template <typename T>
RasterCamera<T> raster_camera(const Camera& camera);

// Throws Error on sizes, focal lengths or an SH degree the kernels cannot take, or a missing
// parameter array.
template <typename T>
void validate_inputs(const GaussianParams<T>& g, const RasterCamera<T>& cam);

// Throws Error unless every target is given (radii may be null when there are no Gaussians).
template <typename T>
void validate_targets(const RenderTargets<T>& out, int count);

// Throws Error unless every parameter gradient array is given (the viewspace ones may be null).
template <typename T>
void validate_grads(const GaussianGrads<T>& grads, int count);

// Renders g seen by cam over background; frame keeps what the backward pass needs.
// Throws Error on invalid sizes or SH degree, or a missing target.
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
