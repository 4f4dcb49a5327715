// SSIM forward and backward on the GPU as separable passes over global memory: a row pass writes
// each pixel's window statistics along its row, a column pass combines them along the column.
// Per pixel, the arithmetic is the CPU kernels' (loss/ssim_rows.cpp) in the same order; only the
// GPU's fused multiply-adds round differently.
#include "loss/cuda/ssim.hpp"
#include "loss/ssim_point.hpp"

namespace iesrgs::loss::cuda {

namespace {

using iesrgs::cuda::check;

constexpr int kRadius = kSsimWindow / 2;
constexpr int kMomentPlanes = 4;  // mean x, mean y, spread, cross
const dim3 kBlock(32, 8);

struct Taps {
  float t[kSsimWindow];
};

Taps taps() {
  Taps w;
  const auto window = ssim_window();
  for (int k = 0; k < kSsimWindow; ++k) w.t[k] = float(window[k]);
  return w;
}

dim3 grid(const ImageShape& shape, int depth) {
  return dim3((shape.width + kBlock.x - 1) / kBlock.x, (shape.height + kBlock.y - 1) / kBlock.y,
              depth);
}

struct Moments {
  float mean_x, mean_y, spread, cross;
};

// Weighted statistics of window samples that are themselves means of sub-windows with their own
// spread and covariance (zero for single pixels): loss/ssim_rows.cpp's combine_moments at one
// pixel.
template <typename Sample>
__device__ Moments combine(const Taps& w, Sample&& sample) {
  Moments m{0.f, 0.f, 0.f, 0.f};
  Moments s[kSsimWindow];
  for (int k = 0; k < kSsimWindow; ++k) {
    s[k] = sample(k);
    m.mean_x += w.t[k] * s[k].mean_x;
    m.mean_y += w.t[k] * s[k].mean_y;
  }
  for (int k = 0; k < kSsimWindow; ++k) {
    const float dx = s[k].mean_x - m.mean_x, dy = s[k].mean_y - m.mean_y;
    m.spread += w.t[k] * (dx * dx + dy * dy);
    m.cross += w.t[k] * dx * dy;
  }
  for (int k = 0; k < kSsimWindow; ++k) {
    m.spread += w.t[k] * s[k].spread;
    m.cross += w.t[k] * s[k].cross;
  }
  return m;
}

// Statistics along the row; pixels beyond the border are zeros, the convolution's padding.
__global__ void forward_rows(const float* x, const float* y, ImageShape shape, Taps w,
                             float* moments) {
  const int col = blockIdx.x * blockDim.x + threadIdx.x,
            row = blockIdx.y * blockDim.y + threadIdx.y;
  if (col >= shape.width || row >= shape.height) return;
  const size_t row_start = (size_t(blockIdx.z) * shape.height + row) * shape.width;
  const Moments m = combine(w, [&](int k) {
    const int c = col - kRadius + k;
    const bool inside = c >= 0 && c < shape.width;
    return Moments{inside ? x[row_start + c] : 0.f, inside ? y[row_start + c] : 0.f, 0.f, 0.f};
  });
  const size_t values = shape.values(), i = row_start + col;
  moments[i] = m.mean_x;
  moments[values + i] = m.mean_y;
  moments[2 * values + i] = m.spread;
  moments[3 * values + i] = m.cross;
}

// Statistics along the column, SSIM and its partials; one thread per pixel over every channel,
// so that the map is summed in the CPU's channel order.
__global__ void forward_columns(ImageShape shape, Taps w, const float* moments, float* map,
                                float* partials, double* sum) {
  const int col = blockIdx.x * blockDim.x + threadIdx.x,
            row = blockIdx.y * blockDim.y + threadIdx.y;
  const bool inside = col < shape.width && row < shape.height;
  double total = 0;
  if (inside) {
    const size_t values = shape.values();
    float map_value = 0;
    for (int c = 0; c < shape.channels; ++c) {
      const Moments m = combine(w, [&](int k) {
        const int r = row - kRadius + k;
        if (r < 0 || r >= shape.height) return Moments{0.f, 0.f, 0.f, 0.f};
        const size_t i = (size_t(c) * shape.height + r) * shape.width + col;
        return Moments{moments[i], moments[values + i], moments[2 * values + i],
                       moments[3 * values + i]};
      });
      const SsimPoint<float> p = ssim_point(m.mean_x, m.mean_y, m.spread, m.cross);
      if (partials) {
        const size_t i = (size_t(c) * shape.height + row) * shape.width + col;
        partials[i] = p.d_mean;
        partials[values + i] = p.d_square;
        partials[2 * values + i] = p.d_cross;
      }
      map_value += p.value * (1.f / float(shape.channels));
      total += p.value;
    }
    if (map) map[size_t(row) * shape.width + col] = map_value;
  }
  for (int offset = 16; offset > 0; offset /= 2)
    total += __shfl_down_sync(0xffffffffu, total, offset);
  if ((threadIdx.y * blockDim.x + threadIdx.x) % 32 == 0 && total != 0) atomicAdd(sum, total);
}

__global__ void write_mean(const double* sum, double count, float* mean) {
  *mean = float(*sum / count);
}

// The weighted partials blurred along the row.
__global__ void backward_rows(ImageShape shape, Taps w, const float* partials, const float* weight,
                              float* blurred) {
  const int col = blockIdx.x * blockDim.x + threadIdx.x,
            row = blockIdx.y * blockDim.y + threadIdx.y;
  if (col >= shape.width || row >= shape.height) return;
  const float inv_channels = 1.f / float(shape.channels);
  const size_t values = shape.values();
  const size_t row_start = (size_t(blockIdx.z) * shape.height + row) * shape.width;
  const float* weight_row = weight + size_t(row) * shape.width;
  for (int plane = 0; plane < kSsimPartialPlanes; ++plane) {
    const float* partial = partials + plane * values + row_start;
    float sum = 0;
    for (int k = 0; k < kSsimWindow; ++k) {
      const int c = col - kRadius + k;
      if (c >= 0 && c < shape.width) sum += w.t[k] * (weight_row[c] * inv_channels * partial[c]);
    }
    blurred[plane * values + row_start + col] = sum;
  }
}

// Blurred along the column too, then the chain rule through the mean, mean square and mean product.
__global__ void backward_columns(const float* x, const float* y, ImageShape shape, Taps w,
                                 const float* blurred, float* grad_x) {
  const int col = blockIdx.x * blockDim.x + threadIdx.x,
            row = blockIdx.y * blockDim.y + threadIdx.y;
  if (col >= shape.width || row >= shape.height) return;
  const size_t values = shape.values();
  const size_t channel_start = size_t(blockIdx.z) * shape.height * shape.width;
  float d[kSsimPartialPlanes];
  for (int plane = 0; plane < kSsimPartialPlanes; ++plane) {
    d[plane] = 0;
    for (int k = 0; k < kSsimWindow; ++k) {
      const int r = row - kRadius + k;
      if (r >= 0 && r < shape.height)
        d[plane] +=
            w.t[k] * blurred[plane * values + channel_start + size_t(r) * shape.width + col];
    }
  }
  const size_t i = channel_start + size_t(row) * shape.width + col;
  grad_x[i] += d[0] + 2 * x[i] * d[1] + y[i] * d[2];
}

}  // namespace

void Ssim::forward(const float* x, const float* y, const ImageShape& shape, float* map,
                   float* partials, float* mean) {
  check_shape(shape, "ssim");
  const Taps w = taps();
  float* moments = planes_.reserve(kMomentPlanes * shape.values());
  double* sum = sum_.reserve(1);
  check(cudaMemsetAsync(sum, 0, sizeof(double), stream_), "cudaMemset");
  forward_rows<<<grid(shape, shape.channels), kBlock, 0, stream_>>>(x, y, shape, w, moments);
  forward_columns<<<grid(shape, 1), kBlock, 0, stream_>>>(shape, w, moments, map, partials, sum);
  write_mean<<<1, 1, 0, stream_>>>(sum, double(shape.values()), mean);
  check(cudaGetLastError(), "ssim");
}

void Ssim::backward(const float* x, const float* y, const ImageShape& shape, const float* partials,
                    const float* weight, float* grad_x) {
  check_shape(shape, "ssim_backward");
  const Taps w = taps();
  float* blurred = planes_.reserve(kSsimPartialPlanes * shape.values());
  backward_rows<<<grid(shape, shape.channels), kBlock, 0, stream_>>>(shape, w, partials, weight,
                                                                     blurred);
  backward_columns<<<grid(shape, shape.channels), kBlock, 0, stream_>>>(x, y, shape, w, blurred,
                                                                        grad_x);
  check(cudaGetLastError(), "ssim_backward");
}

}  // namespace iesrgs::loss::cuda
