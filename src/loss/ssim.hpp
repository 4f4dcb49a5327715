#pragma once
// SSIM exactly as 3DGS computes it (utils/loss_utils.py): per channel, the window statistics come
// from an 11x11 Gaussian window (sigma 1.5) applied as a 'same' convolution with zero padding,
// C1 = 0.01^2, C2 = 0.03^2, images in [0, 1]; SSIM is the mean of the map over pixels and channels.
//
// The kernels are separable (11 taps along rows, then along columns, over bands of rows, one band
// per OpenMP thread) and templated on the scalar: float in production, double for gradient checks.
// A loss whose weights vanish on most pixels (the mask-guided loss's internal reference) runs them
// on the tiles that matter instead of the whole image.
#include <cstddef>
#include <vector>

#include "loss/image_shape.hpp"

namespace iesrgs::loss {

constexpr int kSsimWindow = 11;
constexpr double kSsimSigma = 1.5;
constexpr double kSsimC1 = 0.01 * 0.01;
constexpr double kSsimC2 = 0.03 * 0.03;
// Side of the tiles of a sparse weight. Each tile re-runs the row pass on kSsimWindow / 2 rows and
// columns beyond it; 32 would re-read less but cover more of a thin mask's surroundings, and was
// not faster (docs/BENCHMARKS.md).
constexpr int kSsimTile = 16;

// The partials buffer of ssim() holds, for every value of x, the derivatives of its channel's SSIM
// with respect to the window mean, mean square and mean product of x: kSsimPartialPlanes planes of
// channels x height x width, on the CPU and on the GPU.
constexpr int kSsimPartialPlanes = 3;
inline size_t ssim_partials_size(const ImageShape& shape) {
  return kSsimPartialPlanes * shape.values();
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

// Pixels of rows [row0, row1) and columns [col0, col1).
struct PixelBox {
  int row0, row1, col0, col1;
};

// Where sum_p weight[p] * map[p] needs work: the tiles holding a nonzero weight (whose map and
// partials the forward pass needs) and, when they are sparse, the tiles within the window's
// radius of one (the only pixels with a gradient), out of `tiles` in the whole grid.
struct SsimSupport {
  std::vector<PixelBox> weighted, reached;
  size_t tiles = 0;

  // Tiles beat whole-width bands once most of them can be skipped; `reached` is empty otherwise.
  bool sparse() const { return 2 * weighted.size() < tiles; }
};

template <typename T>
SsimSupport ssim_support(const T* weight, const ImageShape& shape);

// ssim() on the pixels of disjoint boxes only: writes map and partials there and returns the sum
// of the per-channel SSIM over those pixels.
template <typename T>
double ssim_in(const T* x, const T* y, const ImageShape& shape, const std::vector<PixelBox>& boxes,
               T* map, T* partials);

// ssim_backward() for the pixels of disjoint boxes only, which must hold every pixel within the
// window's radius of a nonzero weight. Partials are read only where the weight is nonzero, so the
// buffer may hold anything around the pixels ssim_in computed.
template <typename T>
void ssim_backward_in(const T* x, const T* y, const ImageShape& shape,
                      const std::vector<PixelBox>& boxes, const T* partials, const T* weight,
                      T* grad_x);

}  // namespace iesrgs::loss
