#pragma once
// SSIM exactly as 3DGS computes it (utils/loss_utils.py): per channel, the window statistics come
// from an 11x11 Gaussian window (sigma 1.5) applied as a 'same' convolution with zero padding,
// C1 = 0.01^2, C2 = 0.03^2, images in [0, 1]; SSIM is the mean of the map over pixels and channels.
//
// The kernels are separable (11 taps along rows, then along columns, over bands of rows, one band
// per OpenMP thread) and templated on the scalar: float in production, double for gradient checks.
#include <cstddef>

#include "loss/image_shape.hpp"

namespace iesrgs::loss {

constexpr int kSsimWindow = 11;
constexpr double kSsimSigma = 1.5;
constexpr double kSsimC1 = 0.01 * 0.01;
constexpr double kSsimC2 = 0.03 * 0.03;

// Values the partials buffer of ssim() holds: the derivatives of each channel's SSIM with respect
// to its window mean, mean square and mean product of x (3 x channels x height x width).
inline size_t ssim_partials_size(const ImageShape& shape) {
  return 3 * shape.values();
}

// Mean SSIM of x against y (both CHW). When non-null, `map` receives the per-pixel SSIM averaged
// over channels (height x width) and `partials` what ssim_backward needs.
template <typename T>
double ssim(const T* x, const T* y, const ImageShape& shape, T* map, T* partials);

// Adds to grad_x (CHW) the gradient with respect to x of sum_p weight[p] * map[p], y being a
// constant target; `partials` comes from ssim() on the same images.
template <typename T>
void ssim_backward(const T* x, const T* y, const ImageShape& shape, const T* partials,
                   const T* weight, T* grad_x);

}  // namespace iesrgs::loss
