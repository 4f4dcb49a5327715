#include "loss/photometric.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/math.hpp"
#include "loss/reused_buffer.hpp"
#include "loss/ssim.hpp"

namespace iesrgs::loss {
namespace {

// Mean over channels of |x - y| at pixel p.
template <typename T>
T pixel_l1(const T* x, const T* y, const ImageShape& shape, size_t p) {
  const size_t pixels = shape.pixels();
  T sum = 0;
  for (int c = 0; c < shape.channels; ++c) sum += std::abs(x[c * pixels + p] - y[c * pixels + p]);
  return sum / shape.channels;
}

struct SsimMapSlot;
struct SsimPartialsSlot;
struct L1WeightSlot;
struct SsimWeightSlot;

}  // namespace

template <typename T>
double l1(const T* x, const T* y, const ImageShape& shape) {
  check_shape(shape, "l1");
  const int64_t count = int64_t(shape.values());
  double sum = 0;
#pragma omp parallel for reduction(+ : sum)
  for (int64_t i = 0; i < count; ++i) sum += std::abs(double(x[i]) - double(y[i]));
  return sum / double(count);
}

template <typename T>
void l1_map(const T* x, const T* y, const ImageShape& shape, T* map) {
  check_shape(shape, "l1_map");
#pragma omp parallel for
  for (int64_t p = 0; p < int64_t(shape.pixels()); ++p) map[p] = pixel_l1(x, y, shape, p);
}

template <typename T>
void l1_backward(const T* x, const T* y, const ImageShape& shape, const T* weight, T* grad_x) {
  check_shape(shape, "l1_backward");
  const int64_t pixels = int64_t(shape.pixels());
  const T inv_channels = T(1) / shape.channels;
  // Plane by plane, so that the pixel index needs no division and the loop vectorizes.
#pragma omp parallel
  for (int c = 0; c < shape.channels; ++c) {
    const int64_t plane = c * pixels;
#pragma omp for
    for (int64_t p = 0; p < pixels; ++p)
      grad_x[plane + p] += weight[p] * inv_channels * sign(x[plane + p] - y[plane + p]);
  }
}

template <typename T>
double dssim(const T* x, const T* y, const ImageShape& shape) {
  return 1.0 - ssim<T>(x, y, shape, nullptr, nullptr);
}

template <typename T>
void photometric_map(const T* x, const T* y, const ImageShape& shape, double lambda, T* map) {
  ssim<T>(x, y, shape, map, nullptr);
  const T l1_weight = T(1 - lambda), ssim_weight = T(lambda);
#pragma omp parallel for
  for (int64_t p = 0; p < int64_t(shape.pixels()); ++p)
    map[p] = l1_weight * pixel_l1(x, y, shape, p) + ssim_weight * (1 - map[p]);
}

template <typename T>
double weighted_photometric_loss(const T* x, const T* y, const ImageShape& shape, double lambda,
                                 const T* weight, T* grad_x) {
  check_shape(shape, "weighted_photometric_loss");
  const size_t pixels = shape.pixels();
  const SsimSupport support = ssim_support(weight, shape);
  const bool sparse = support.sparse();
  // A sparse weight leaves both unwritten outside its tiles, where the weight is zero.
  T* ssim_map = reused_buffer<T, SsimMapSlot>(pixels);
  T* partials = grad_x ? reused_buffer<T, SsimPartialsSlot>(ssim_partials_size(shape)) : nullptr;
  if (sparse)
    ssim_in<T>(x, y, shape, support.weighted, ssim_map, partials);
  else
    ssim<T>(x, y, shape, ssim_map, partials);
  double sum = 0;
#pragma omp parallel for reduction(+ : sum)
  for (int64_t p = 0; p < int64_t(pixels); ++p) {
    if (weight[p] == T(0)) continue;
    const double l1 = pixel_l1(x, y, shape, p);
    sum += double(weight[p]) * ((1 - lambda) * l1 + lambda * (1 - double(ssim_map[p])));
  }
  if (grad_x) {
    // The weights of the two terms' maps, in one pass over the pixels.
    T* l1_weight = reused_buffer<T, L1WeightSlot>(pixels);
    T* ssim_weight = reused_buffer<T, SsimWeightSlot>(pixels);
#pragma omp parallel for
    for (int64_t p = 0; p < int64_t(pixels); ++p) {
      l1_weight[p] = T((1 - lambda) * weight[p]);
      ssim_weight[p] = T(-lambda * weight[p]);
    }
    l1_backward(x, y, shape, l1_weight, grad_x);
    if (sparse)
      ssim_backward_in(x, y, shape, support.reached, partials, ssim_weight, grad_x);
    else
      ssim_backward(x, y, shape, partials, ssim_weight, grad_x);
  }
  return sum;
}

template <typename T>
double photometric_loss(const T* x, const T* y, const ImageShape& shape, double lambda, T* grad_x) {
  check_shape(shape, "photometric_loss");
  const std::vector<T> mean_weight(shape.pixels(), T(1.0 / double(shape.pixels())));
  return weighted_photometric_loss(x, y, shape, lambda, mean_weight.data(), grad_x);
}

#define IESRGS_INSTANTIATE_PHOTOMETRIC(T)                                                  \
  template double l1(const T*, const T*, const ImageShape&);                               \
  template void l1_map(const T*, const T*, const ImageShape&, T*);                         \
  template void l1_backward(const T*, const T*, const ImageShape&, const T*, T*);          \
  template double dssim(const T*, const T*, const ImageShape&);                            \
  template void photometric_map(const T*, const T*, const ImageShape&, double, T*);        \
  template double weighted_photometric_loss(const T*, const T*, const ImageShape&, double, \
                                            const T*, T*);                                 \
  template double photometric_loss(const T*, const T*, const ImageShape&, double, T*);
IESRGS_INSTANTIATE_PHOTOMETRIC(float)
IESRGS_INSTANTIATE_PHOTOMETRIC(double)
#undef IESRGS_INSTANTIATE_PHOTOMETRIC

}  // namespace iesrgs::loss
