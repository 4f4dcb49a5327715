#pragma once
// Photometric losses of a rendered image x against a constant reference y (CHW arrays): L1,
// D-SSIM and their mix (1 - lambda) * L1 + lambda * D-SSIM, as means and as per-pixel maps
// (channels averaged) whose mean is the loss.
#include "loss/image_shape.hpp"

namespace iesrgs::loss {

// 3DGS's mix, 0.8 * L1 + 0.2 * D-SSIM: the default of every training, per reference in fusion.
constexpr double kDssimWeight = 0.2;

// Mean absolute error over all pixels and channels.
template <typename T>
double l1(const T* x, const T* y, const ImageShape& shape);

// map[p] = mean over channels of |x - y| at pixel p.
template <typename T>
void l1_map(const T* x, const T* y, const ImageShape& shape, T* map);

// Adds to grad_x the gradient of sum_p weight[p] * l1_map[p]; |t| has derivative 0 at t = 0, as
// in torch.
template <typename T>
void l1_backward(const T* x, const T* y, const ImageShape& shape, const T* weight, T* grad_x);

// 1 - SSIM.
template <typename T>
double dssim(const T* x, const T* y, const ImageShape& shape);

// map[p] = (1 - lambda) * l1_map[p] + lambda * (1 - ssim_map[p]).
template <typename T>
void photometric_map(const T* x, const T* y, const ImageShape& shape, double lambda, T* map);

// sum_p weight[p] * photometric_map[p]; adds its gradient to grad_x when grad_x is non-null.
template <typename T>
double weighted_photometric_loss(const T* x, const T* y, const ImageShape& shape, double lambda,
                                 const T* weight, T* grad_x);

// (1 - lambda) * L1 + lambda * D-SSIM; adds its gradient to grad_x when grad_x is non-null.
template <typename T>
double photometric_loss(const T* x, const T* y, const ImageShape& shape, double lambda, T* grad_x);

}  // namespace iesrgs::loss
