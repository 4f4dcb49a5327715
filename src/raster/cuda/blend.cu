// Per-tile alpha blending on the GPU, one thread block per 16x16 tile and one thread per pixel.
// The tile's splats pass through shared memory a batch at a time. Per pixel, the arithmetic is
// the CPU kernels' (raster/cpu/blend.cpp): the same alpha rule, cut-offs and gradient formulas.
// The backward pass sums each splat's per-pixel partials within a warp, then adds them to the
// splat's gradient with one atomic per field and warp.
#include "raster/blend_math.hpp"
#include "raster/cuda/kernels.cuh"

namespace iesrgs::raster::cuda {

namespace {

constexpr int kThreads = kTilePixels;
constexpr unsigned kFullWarp = 0xffffffffu;

// The pixel a thread owns in its block's tile.
struct TilePixel {
  int x, y;
  bool inside;  // false in the part of a border tile that lies off the image
  size_t index;

  __device__ TilePixel(int tiles_x, int width, int height) {
    x = int(blockIdx.x) % tiles_x * kTileSize + int(threadIdx.x) % kTileSize;
    y = int(blockIdx.x) / tiles_x * kTileSize + int(threadIdx.x) / kTileSize;
    inside = x < width && y < height;
    index = size_t(y) * width + x;
  }
};

// splat_alpha of the CPU kernels for one pixel: min(0.99, weight), zero where skipped.
__device__ float splat_alpha(float power, float weight) {
  const float alpha = fminf(weight, kMaxAlpha);
  return alpha < kMinAlpha || power > 0.f ? 0.f : alpha;
}

__global__ void __launch_bounds__(kThreads)
    blend_forward_kernel(const uint32_t* tile_start, const uint32_t* entry_gaussian,
                         const Splat<float>* splats, int tiles_x, int width, int height,
                         Background background, float* image, float* alpha, float* depth,
                         PixelState state) {
  __shared__ Splat<float> batch[kThreads];
  const TilePixel px(tiles_x, width, height);
  const float cx = float(px.x) + 0.5f, cy = float(px.y) + 0.5f;
  const uint32_t begin = tile_start[blockIdx.x], end = tile_start[blockIdx.x + 1];
  bool done = !px.inside;
  float transmittance = 1.f, color[3] = {0.f, 0.f, 0.f}, blended_depth = 0.f;
  uint32_t contributors = 0;

  for (uint32_t base = begin; base < end; base += kThreads) {
    // Every pixel stopped: the rest of the tile's splats are hidden.
    if (__syncthreads_count(done) == kThreads) break;
    if (base + threadIdx.x < end) batch[threadIdx.x] = splats[entry_gaussian[base + threadIdx.x]];
    __syncthreads();
    const uint32_t n = min(uint32_t(kThreads), end - base);
    for (uint32_t k = 0; k < n && !done; ++k) {
      const Splat<float>& s = batch[k];
      const float power = splat_power(s, s.x - cx, s.y - cy);
      const float a = splat_alpha(power, s.opacity * falloff_exp(power));
      if (a == 0.f) continue;
      const float next = transmittance * (1.f - a);
      // 3DGS stops a pixel before blending the splat that would drop it below the cut-off.
      if (next < kMinTransmittance) {
        done = true;
        break;
      }
      const float w = a * transmittance;
      for (int c = 0; c < 3; ++c) color[c] += w * s.color[c];
      blended_depth += w * s.depth;
      transmittance = next;
      contributors = base - begin + k + 1;
    }
  }
  if (!px.inside) return;
  const size_t plane = size_t(width) * height;
  for (int c = 0; c < 3; ++c)
    image[c * plane + px.index] = color[c] + transmittance * background.rgb[c];
  alpha[px.index] = 1.f - transmittance;
  depth[px.index] = blended_depth;
  state.final_transmittance[px.index] = transmittance;
  state.contributors[px.index] = contributors;
}

constexpr int kGradFields = SplatGrad<float>::kFields;  // all floats (raster/types.hpp)

// Adds the warp's sum of one splat's per-pixel partials to its gradient.
__device__ void add_warp_sum(const SplatGrad<float>& partial, SplatGrad<float>* target) {
  float sum[kGradFields];
  memcpy(sum, &partial, sizeof sum);
  for (int f = 0; f < kGradFields; ++f)
    for (int offset = 16; offset > 0; offset /= 2)
      sum[f] += __shfl_down_sync(kFullWarp, sum[f], offset);
  if (threadIdx.x % 32 == 0) {
    float* out = reinterpret_cast<float*>(target);
    for (int f = 0; f < kGradFields; ++f)
      if (sum[f] != 0.f) atomicAdd(out + f, sum[f]);
  }
}

__global__ void __launch_bounds__(kThreads)
    blend_backward_kernel(const uint32_t* tile_start, const uint32_t* entry_gaussian,
                          const Splat<float>* splats, int tiles_x, int width, int height,
                          Background background, PixelState state, const float* dimage,
                          const float* dalpha, const float* ddepth, SplatGrad<float>* splat_grads) {
  __shared__ Splat<float> batch[kThreads];
  __shared__ uint32_t batch_gaussian[kThreads];
  __shared__ uint32_t tile_last;
  const TilePixel px(tiles_x, width, height);
  const float cx = float(px.x) + 0.5f, cy = float(px.y) + 0.5f;
  const size_t plane = size_t(width) * height;

  // Pixels off the image keep transmittance 1 and no contributors: they add nothing.
  float transmittance = 1.f, dcolor[3] = {0.f, 0.f, 0.f}, dz = 0.f, dfinal = 0.f, behind = 0.f;
  uint32_t contributors = 0;
  if (px.inside) {
    transmittance = state.final_transmittance[px.index];
    contributors = state.contributors[px.index];
    float dlight = dalpha ? dalpha[px.index] : 0.f;
    for (int c = 0; c < 3; ++c) {
      dcolor[c] = dimage ? dimage[c * plane + px.index] : 0.f;
      dlight -= background.rgb[c] * dcolor[c];
    }
    // How the loss moves with the light that passes every splat.
    dfinal = transmittance * dlight;
    dz = ddepth ? ddepth[px.index] : 0.f;
  }
  if (threadIdx.x == 0) tile_last = 0;
  __syncthreads();
  atomicMax(&tile_last, contributors);
  __syncthreads();
  const uint32_t begin = tile_start[blockIdx.x];

  for (uint32_t batch_end = tile_last; batch_end > 0;) {
    const uint32_t batch_begin = batch_end > uint32_t(kThreads) ? batch_end - kThreads : 0;
    __syncthreads();
    if (batch_begin + threadIdx.x < batch_end) {
      const uint32_t g = entry_gaussian[begin + batch_begin + threadIdx.x];
      batch_gaussian[threadIdx.x] = g;
      batch[threadIdx.x] = splats[g];
    }
    __syncthreads();
    for (uint32_t k = batch_end; k-- > batch_begin;) {
      const Splat<float>& s = batch[k - batch_begin];
      SplatGrad<float> d{};
      bool touched = false;
      if (k < contributors) {
        const float dx = s.x - cx, dy = s.y - cy;
        const float power = splat_power(s, dx, dy);
        const float falloff = falloff_exp(power);
        const float weight = s.opacity * falloff;
        const float a = splat_alpha(power, weight);
        if (a > 0.f) {
          touched = true;
          const float inv_opaque = 1.f / (1.f - a);
          const float t_front = transmittance * inv_opaque;
          const float w = a * t_front;
          // The splat's own loss-weighted color and depth against what it hides.
          float value = s.depth * dz;
          d.depth = w * dz;
          for (int c = 0; c < 3; ++c) {
            d.color[c] = w * dcolor[c];
            value += s.color[c] * dcolor[c];
          }
          const float da = t_front * (value - behind) + inv_opaque * dfinal;
          behind = a * value + (1.f - a) * behind;
          transmittance = t_front;
          // Alpha capped at 0.99 passes no gradient to opacity or shape.
          if (weight <= kMaxAlpha) {
            d.opacity = da * falloff;
            const float dpower = a * da;
            d.x = -dpower * (s.conic_xx * dx + s.conic_xy * dy);
            d.y = -dpower * (s.conic_yy * dy + s.conic_xy * dx);
            d.abs_x = fabsf(d.x);
            d.abs_y = fabsf(d.y);
            d.conic_xx = -0.5f * dx * dx * dpower;
            d.conic_xy = -dx * dy * dpower;
            d.conic_yy = -0.5f * dy * dy * dpower;
          }
        }
      }
      if (__any_sync(kFullWarp, touched))
        add_warp_sum(d, splat_grads + batch_gaussian[k - batch_begin]);
    }
    batch_end = batch_begin;
  }
}

}  // namespace

void blend_forward(const DeviceBins& bins, const Splat<float>* splats, int width, int height,
                   Background background, const RenderTargets<float>& out, PixelState state,
                   cudaStream_t stream) {
  blend_forward_kernel<<<bins.tile_count(), kThreads, 0, stream>>>(
      bins.tile_start, bins.entry_gaussian, splats, bins.tiles_x, width, height, background,
      out.image, out.alpha, out.depth, state);
  check(cudaGetLastError(), "blend_forward");
}

void blend_backward(const DeviceBins& bins, const Splat<float>* splats, int width, int height,
                    Background background, PixelState state, const PixelGrads<float>& pixel_grads,
                    SplatGrad<float>* splat_grads, cudaStream_t stream) {
  blend_backward_kernel<<<bins.tile_count(), kThreads, 0, stream>>>(
      bins.tile_start, bins.entry_gaussian, splats, bins.tiles_x, width, height, background, state,
      pixel_grads.image, pixel_grads.alpha, pixel_grads.depth, splat_grads);
  check(cudaGetLastError(), "blend_backward");
}

}  // namespace iesrgs::raster::cuda
