#pragma once
// Plain data shared by the raster kernels: camera, Gaussian parameters, per-Gaussian splats.
#include <cstdint>
#include <vector>

#include "core/hd.hpp"

namespace iesrgs::raster {

constexpr int kTileSize = 16;
constexpr int kTilePixels = kTileSize * kTileSize;

// Pinhole camera, OpenCV convention (x right, y down, z forward), pixel centers at +0.5.
template <typename T>
struct RasterCamera {
  int width = 0, height = 0;
  T fx = 0, fy = 0, cx = 0, cy = 0;
  T rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // world-to-camera, row-major
  T translation[3] = {0, 0, 0};                 // world-to-camera
};

// Non-owning view of N Gaussians, row-major arrays.
template <typename T>
struct GaussianParams {
  int count = 0;
  int sh_degree = 0;                  // active degree 0..3
  const T* means = nullptr;           // (N, 3)
  const T* log_scales = nullptr;      // (N, 3)
  const T* quats = nullptr;           // (N, 4) w x y z, unnormalized
  const T* opacity_logits = nullptr;  // (N)
  const T* sh_dc = nullptr;           // (N, 1, 3) SH band 0
  const T* sh_rest = nullptr;         // (N, 15, 3) SH bands 1..3
  const T* filter_std = nullptr;      // (N) Mip-Splatting 3D filter; nullptr means none
  bool antialiased = true;  // Mip-Splatting's 2D filter; false: 3DGS's dilation ("classic")
};

// GaussianParams viewing the arrays of `storage` (host or device arrays with data() and size(),
// named as in GaussianBuffers); no 3D filter where filter_std is empty.
template <typename T, typename Storage>
GaussianParams<T> params_of(const Storage& storage) {
  GaussianParams<T> g;
  g.count = int(storage.opacity_logits.size());
  g.sh_degree = storage.sh_degree;
  g.means = storage.means.data();
  g.log_scales = storage.log_scales.data();
  g.quats = storage.quats.data();
  g.opacity_logits = storage.opacity_logits.data();
  g.sh_dc = storage.sh_dc.data();
  g.sh_rest = storage.sh_rest.data();
  g.filter_std = storage.filter_std.size() > 0 ? storage.filter_std.data() : nullptr;
  g.antialiased = storage.antialiased;
  return g;
}

// Owning storage behind GaussianParams: the benchmarks' scenes and the kernel tests' scenes.
template <typename T>
struct GaussianBuffers {
  int sh_degree = 3;
  std::vector<T> means, log_scales, quats, opacity_logits, sh_dc, sh_rest, filter_std;
  bool antialiased = true;

  int count() const { return int(opacity_logits.size()); }
  GaussianParams<T> params() const { return params_of<T>(*this); }
};

// Gradients with respect to GaussianParams, same shapes, plus the screen-space gradients that
// drive densification.
template <typename T>
struct GaussianGrads {
  T* means = nullptr;
  T* log_scales = nullptr;
  T* quats = nullptr;
  T* opacity_logits = nullptr;
  T* sh_dc = nullptr;
  T* sh_rest = nullptr;
  // (N, 2) gradient of the projected mean in NDC units ([-1, 1] across the image), as 3DGS
  // reports it, so its 2e-4 densification threshold applies; and the sum over pixels of the
  // absolute per-pixel contributions (AbsGS's statistic, gsplat's absgrad), same units.
  T* viewspace = nullptr;
  T* viewspace_abs = nullptr;
};

// What the blending needs of a projected Gaussian, precomputed once per frame.
template <typename T>
struct Splat {
  T x, y;                          // mean in pixels
  T conic_xx, conic_xy, conic_yy;  // inverse of the filtered 2D covariance
  T opacity;                       // after sigmoid and both Mip-Splatting filters
  T color[3];
  T depth;  // camera-space z
  // Footprint, for loop bounds only: alpha is below 1/255 wherever the Mahalanobis distance
  // d^T conic d exceeds `cutoff` (0 when the splat can never reach it); conic_det = det(conic).
  T cutoff, conic_det;
};

// Gradient of the loss with respect to every Splat field, plus the absolute screen-space sums.
template <typename T>
struct SplatGrad {
  T x, y;
  T conic_xx, conic_xy, conic_yy;
  T opacity;
  T color[3];
  T depth;
  T abs_x, abs_y;

  // The members below name every field; a new field must join them (kFields).
  static constexpr int kFields = 12;

  IESRGS_HD bool is_zero() const {
    return x == T(0) && y == T(0) && conic_xx == T(0) && conic_xy == T(0) && conic_yy == T(0) &&
           opacity == T(0) && color[0] == T(0) && color[1] == T(0) && color[2] == T(0) &&
           depth == T(0) && abs_x == T(0) && abs_y == T(0);
  }
  IESRGS_HD SplatGrad& operator+=(const SplatGrad& o) {
    x += o.x;
    y += o.y;
    conic_xx += o.conic_xx;
    conic_xy += o.conic_xy;
    conic_yy += o.conic_yy;
    opacity += o.opacity;
    for (int c = 0; c < 3; ++c) color[c] += o.color[c];
    depth += o.depth;
    abs_x += o.abs_x;
    abs_y += o.abs_y;
    return *this;
  }
};
static_assert(sizeof(SplatGrad<float>) == SplatGrad<float>::kFields * sizeof(float),
              "SplatGrad gained a field that is_zero and operator+= do not name");

// Half-open pixel rectangle [x0, x1) x [y0, y1) outside which a splat's alpha is below 1/255.
struct PixelRect {
  int32_t x0, y0, x1, y1;

  IESRGS_HD bool empty() const { return x0 >= x1 || y0 >= y1; }
};

}  // namespace iesrgs::raster
