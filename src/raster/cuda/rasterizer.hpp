#pragma once
// The differentiable Gaussian rasterizer on an NVIDIA GPU: the CPU rasterizer's math
// (raster/project.hpp, raster/blend_math.hpp) in CUDA kernels, behind the same inputs and outputs.
// Every array handed in or out is in device memory; float only. Plain C++ header: callers need
// the CUDA runtime's headers, not its compiler.
#include <memory>

#include "core/cuda/device_array.hpp"
#include "raster/frame.hpp"
#include "raster/rasterizer.hpp"

struct CUstream_st;

namespace iesrgs::raster::cuda {

// Gaussian parameters copied to the device.
struct DeviceGaussians {
  explicit DeviceGaussians(const GaussianBuffers<float>& host);
  GaussianParams<float> params() const;

  int sh_degree;
  bool antialiased;
  iesrgs::cuda::DeviceArray<float> means, log_scales, quats, opacity_logits, sh_dc, sh_rest,
      filter_std;
};

// Renders frames and their backward passes; keeps the device buffers of the latest frame, which
// grow with the scene and are reused.
class Rasterizer {
 public:
  // Work is queued on `stream` (the default stream when null).
  explicit Rasterizer(CUstream_st* stream = nullptr);
  ~Rasterizer();
  Rasterizer(const Rasterizer&) = delete;
  Rasterizer& operator=(const Rasterizer&) = delete;

  // As raster::rasterize_forward.
  void forward(const GaussianParams<float>& g, const RasterCamera<float>& cam,
               const float background[3], const RenderTargets<float>& out);
  // As raster::rasterize_backward, for the latest forward call with the same g.
  void backward(const GaussianParams<float>& g, const PixelGrads<float>& pixel_grads,
                const GaussianGrads<float>& grads);

  // Waits for the queued work; then timings() holds the stages of the latest calls.
  void synchronize();
  RasterTimings timings() const;
  // Splat-tile pairs of the latest frame.
  size_t entry_count() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace iesrgs::raster::cuda
