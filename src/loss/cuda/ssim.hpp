#pragma once
// The SSIM of loss/ssim.hpp on device arrays (CHW, float): the same window, constants and
// numerics (window statistics from deviations, per row then per column), one thread per pixel.
#include "core/cuda/device_array.hpp"
#include "loss/image_shape.hpp"

struct CUstream_st;

namespace iesrgs::loss::cuda {

// Owns the intermediate planes, which grow with the largest image seen.
class Ssim {
 public:
  // Work is queued on `stream` (the default stream when null).
  explicit Ssim(CUstream_st* stream = nullptr) : stream_(stream) {}

  // As loss::ssim: writes the mean SSIM of x against y to the device float `mean`; map (H x W)
  // and partials (ssim_partials_size(shape)) are filled when non-null. Queues work without
  // waiting for it, so that a training step does not stop the host once per loss term.
  void forward(const float* x, const float* y, const ImageShape& shape, float* map, float* partials,
               float* mean);
  // As loss::ssim_backward: adds to grad_x the gradient of sum_p weight[p] * map[p].
  void backward(const float* x, const float* y, const ImageShape& shape, const float* partials,
                const float* weight, float* grad_x);

 private:
  CUstream_st* stream_;
  iesrgs::cuda::DeviceArray<float> planes_;
  iesrgs::cuda::DeviceArray<double> sum_;
};

}  // namespace iesrgs::loss::cuda
