#include "loss/texture_fusion.hpp"

#include <cmath>

#include "loss/photometric.hpp"

namespace iesrgs::loss {

template <typename T>
std::vector<uint8_t> discrepancy_mask(const T* internal, const T* external, const ImageShape& shape,
                                      double threshold) {
  check_shape(shape, "discrepancy_mask");
  constexpr double kEpsilon = 1e-6;
  const size_t pixels = shape.pixels();
  std::vector<uint8_t> mask(pixels);
#pragma omp parallel for
  for (int64_t p = 0; p < int64_t(pixels); ++p) {
    double sum = 0;
    for (int c = 0; c < shape.channels; ++c) {
      const double i = internal[c * pixels + p], e = external[c * pixels + p];
      sum += std::abs(i - e) / (i + kEpsilon);
    }
    mask[p] = sum / shape.channels >= threshold;
  }
  return mask;
}

template <typename T>
double masked_texture_loss(const T* render, const T* internal, const T* external,
                           const uint8_t* mask, const ImageShape& shape, double lambda,
                           T* grad_render) {
  check_shape(shape, "masked_texture_loss");
  const size_t pixels = shape.pixels();
  const T mean_weight = T(1.0 / double(pixels));
  std::vector<T> internal_weight(pixels), external_weight(pixels);
  for (size_t p = 0; p < pixels; ++p) {
    internal_weight[p] = mask[p] ? mean_weight : T(0);
    external_weight[p] = mask[p] ? T(0) : mean_weight;
  }
  return weighted_photometric_loss(render, internal, shape, lambda, internal_weight.data(),
                                   grad_render) +
         weighted_photometric_loss(render, external, shape, lambda, external_weight.data(),
                                   grad_render);
}

template std::vector<uint8_t> discrepancy_mask(const float*, const float*, const ImageShape&,
                                               double);
template std::vector<uint8_t> discrepancy_mask(const double*, const double*, const ImageShape&,
                                               double);
template double masked_texture_loss(const float*, const float*, const float*, const uint8_t*,
                                    const ImageShape&, double, float*);
template double masked_texture_loss(const double*, const double*, const double*, const uint8_t*,
                                    const ImageShape&, double, double*);

}  // namespace iesrgs::loss
