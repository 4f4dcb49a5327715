#include "loss/texture_fusion.hpp"

#include <cmath>

#include "core/error.hpp"
#include "loss/photometric.hpp"
#include "loss/reused_buffer.hpp"

namespace iesrgs::loss {

namespace {
struct InternalWeightSlot;
struct ExternalWeightSlot;
}  // namespace

template <typename T>
std::vector<T> discrepancy_map(const T* internal, const T* external, const ImageShape& shape) {
  check_shape(shape, "discrepancy_map");
  constexpr double kEpsilon = 1e-6;
  const size_t pixels = shape.pixels();
  std::vector<T> map(pixels);
#pragma omp parallel for
  for (int64_t p = 0; p < int64_t(pixels); ++p) {
    double sum = 0;
    for (int c = 0; c < shape.channels; ++c) {
      const double i = internal[c * pixels + p], e = external[c * pixels + p];
      sum += std::abs(i - e) / (i + kEpsilon);
    }
    map[p] = T(sum / shape.channels);
  }
  return map;
}

template <typename T>
std::vector<uint8_t> discrepancy_mask(const T* internal, const T* external, const ImageShape& shape,
                                      double threshold) {
  const std::vector<T> map = discrepancy_map(internal, external, shape);
  std::vector<uint8_t> mask(map.size());
  for (size_t p = 0; p < map.size(); ++p) mask[p] = map[p] >= threshold;
  return mask;
}

template <typename T>
double guided_texture_loss(const T* render, const T* internal, const T* external,
                           const T* internal_share, const ImageShape& shape, double lambda,
                           T* grad_render) {
  check_shape(shape, "guided_texture_loss");
  const int64_t pixels = int64_t(shape.pixels());
  const T mean_weight = T(1.0 / double(pixels));
  T* internal_weight = reused_buffer<T, InternalWeightSlot>(pixels);
  T* external_weight = reused_buffer<T, ExternalWeightSlot>(pixels);
  bool uses_internal = false, uses_external = false;
#pragma omp parallel for reduction(|| : uses_internal, uses_external)
  for (int64_t p = 0; p < pixels; ++p) {
    internal_weight[p] = internal_share[p] * mean_weight;
    external_weight[p] = (1 - internal_share[p]) * mean_weight;
    uses_internal = uses_internal || internal_weight[p] != 0;
    uses_external = uses_external || external_weight[p] != 0;
  }
  if (uses_internal && !internal) fail("guided_texture_loss: internal share without an image");
  if (uses_external && !external) fail("guided_texture_loss: external share without an image");
  double loss = 0;
  if (uses_internal)
    loss +=
        weighted_photometric_loss(render, internal, shape, lambda, internal_weight, grad_render);
  if (uses_external)
    loss +=
        weighted_photometric_loss(render, external, shape, lambda, external_weight, grad_render);
  return loss;
}

template std::vector<float> discrepancy_map(const float*, const float*, const ImageShape&);
template std::vector<double> discrepancy_map(const double*, const double*, const ImageShape&);
template std::vector<uint8_t> discrepancy_mask(const float*, const float*, const ImageShape&,
                                               double);
template std::vector<uint8_t> discrepancy_mask(const double*, const double*, const ImageShape&,
                                               double);
template double guided_texture_loss(const float*, const float*, const float*, const float*,
                                    const ImageShape&, double, float*);
template double guided_texture_loss(const double*, const double*, const double*, const double*,
                                    const ImageShape&, double, double*);

}  // namespace iesrgs::loss
