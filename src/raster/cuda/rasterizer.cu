// The CUDA rasterizer's stages in order, with the frame's device buffers between them.
#include "raster/cuda/rasterizer.hpp"

#include <algorithm>

#include "raster/cuda/kernels.cuh"

namespace iesrgs::raster::cuda {

DeviceGaussians::DeviceGaussians(const GaussianBuffers<float>& host)
    : sh_degree(host.sh_degree),
      antialiased(host.antialiased),
      means(host.means),
      log_scales(host.log_scales),
      quats(host.quats),
      opacity_logits(host.opacity_logits),
      sh_dc(host.sh_dc),
      sh_rest(host.sh_rest),
      filter_std(host.filter_std) {}

GaussianParams<float> DeviceGaussians::params() const {
  return params_of<float>(*this);
}

namespace {

// Marks the stages of a pass on the stream; elapsed times are read once the stream has reached
// them.
class StageEvents {
 public:
  static constexpr int kMarks = 4;

  StageEvents() {
    for (cudaEvent_t& e : events_) check(cudaEventCreate(&e), "cudaEventCreate");
  }
  ~StageEvents() {
    for (cudaEvent_t e : events_) cudaEventDestroy(e);
  }
  StageEvents(const StageEvents&) = delete;
  StageEvents& operator=(const StageEvents&) = delete;

  void mark(int i, cudaStream_t stream) {
    check(cudaEventRecord(events_[i], stream), "cudaEventRecord");
    recorded_ = std::max(recorded_, i + 1);
  }
  // Milliseconds from mark i to mark i + 1; 0 where they were not recorded.
  double lap(int i) const {
    if (i + 1 >= recorded_) return 0;
    float ms = 0;
    check(cudaEventElapsedTime(&ms, events_[i], events_[i + 1]), "cudaEventElapsedTime");
    return ms;
  }

 private:
  cudaEvent_t events_[kMarks];
  int recorded_ = 0;
};

}  // namespace

struct Rasterizer::State {
  cudaStream_t stream = nullptr;
  RasterCamera<float> camera;
  Background background{};
  int count = 0;
  DeviceArray<Splat<float>> splats;
  DeviceArray<PixelRect> rects;
  DeviceArray<uint64_t> tiles_touched;
  TileBinner binner;
  DeviceBins bins;
  DeviceArray<float> final_transmittance;
  DeviceArray<uint32_t> contributors;
  DeviceArray<SplatGrad<float>> splat_grads;
  StageEvents forward_events, backward_events;

  PixelState pixel_state() const { return {final_transmittance.data(), contributors.data()}; }
};

Rasterizer::Rasterizer(CUstream_st* stream) : state_(std::make_unique<State>()) {
  state_->stream = stream;
}

Rasterizer::~Rasterizer() = default;

void Rasterizer::forward(const GaussianParams<float>& g, const RasterCamera<float>& cam,
                         const float background[3], const RenderTargets<float>& out) {
  validate_inputs(g, cam);
  validate_targets(out, g.count);
  State& s = *state_;
  s.camera = cam;
  s.count = g.count;
  for (int c = 0; c < 3; ++c) s.background.rgb[c] = background[c];
  const size_t pixels = size_t(cam.width) * cam.height;
  s.final_transmittance.reserve(pixels);
  s.contributors.reserve(pixels);

  s.forward_events.mark(0, s.stream);
  project_forward(g, cam, s.splats.reserve(g.count), s.rects.reserve(g.count), out.radii,
                  s.tiles_touched.reserve(g.count), s.stream);
  s.forward_events.mark(1, s.stream);
  s.bins = s.binner.bin(s.splats.data(), s.rects.data(), s.tiles_touched.data(), g.count, cam.width,
                        cam.height, s.stream);
  s.forward_events.mark(2, s.stream);
  blend_forward(s.bins, s.splats.data(), cam.width, cam.height, s.background, out, s.pixel_state(),
                s.stream);
  s.forward_events.mark(3, s.stream);
}

void Rasterizer::backward(const GaussianParams<float>& g, const PixelGrads<float>& pixel_grads,
                          const GaussianGrads<float>& grads) {
  State& s = *state_;
  if (g.count != s.count)
    fail("rasterizer: backward got {} Gaussians, forward rendered {}", g.count, s.count);
  validate_grads(grads, g.count);
  const size_t n = size_t(g.count);
  for (const GradArray<float>& a : grad_arrays(grads, n))
    if (a.data) check(cudaMemsetAsync(a.data, 0, a.size * sizeof(float), s.stream), "cudaMemset");
  SplatGrad<float>* splat_grads = s.splat_grads.reserve(n);
  check(cudaMemsetAsync(splat_grads, 0, n * sizeof(SplatGrad<float>), s.stream), "cudaMemset");

  s.backward_events.mark(0, s.stream);
  blend_backward(s.bins, s.splats.data(), s.camera.width, s.camera.height, s.background,
                 s.pixel_state(), pixel_grads, splat_grads, s.stream);
  s.backward_events.mark(1, s.stream);
  project_backward(g, s.camera, splat_grads, grads, s.stream);
  s.backward_events.mark(2, s.stream);
}

void Rasterizer::synchronize() {
  check(cudaStreamSynchronize(state_->stream), "rasterizer");
}

RasterTimings Rasterizer::timings() const {
  const State& s = *state_;
  RasterTimings t;
  t.project = s.forward_events.lap(0);
  t.bin = s.forward_events.lap(1);
  t.blend = s.forward_events.lap(2);
  t.blend_backward = s.backward_events.lap(0);
  t.project_backward = s.backward_events.lap(1);
  return t;
}

size_t Rasterizer::entry_count() const {
  return state_->bins.entries;
}

}  // namespace iesrgs::raster::cuda
