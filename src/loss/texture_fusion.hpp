#pragma once
// Mask-guided texture loss of the fusion stage: each pixel of the render is supervised by the
// internal image I (the LR model's SR render) where I and the external image E (2D SR) disagree,
// and by E elsewhere.
#include <cstdint>
#include <vector>

#include "loss/image_shape.hpp"

namespace iesrgs::loss {

// Discrepancy thresholds T of the paper.
constexpr double kDiscrepancyThresholdSynthetic = 0.6;
constexpr double kDiscrepancyThresholdReal = 0.9;

// D(p) = mean over channels of |I - E| / (I + 1e-6), the ratio taken per channel before
// averaging.
template <typename T>
std::vector<T> discrepancy_map(const T* internal, const T* external, const ImageShape& shape);

// M(p) = [D(p) >= threshold], one byte per pixel; 1 selects the internal image.
template <typename T>
std::vector<uint8_t> discrepancy_mask(const T* internal, const T* external, const ImageShape& shape,
                                      double threshold);

// L_tex = mean_p(S(p) * l_I(p) + (1 - S(p)) * l_E(p)), l_ref the photometric map
// (1 - lambda) * l1_map + lambda * (1 - ssim_map) of the render against ref, and S the internal
// share per pixel: the mask M for IE-SRGS, 0.5 to average both references, 0 for E alone (then
// `internal` may be null), 1 for I alone (then `external` may be null). A reference whose share
// is zero everywhere is not evaluated. Adds the gradient with respect to the render to
// grad_render when non-null.
template <typename T>
double guided_texture_loss(const T* render, const T* internal, const T* external,
                           const T* internal_share, const ImageShape& shape, double lambda,
                           T* grad_render);

}  // namespace iesrgs::loss
