// Runs the active instruction-set variant (core/cpu_isa.hpp) of the projection and blend passes,
// chosen once per call. Compiled with the build's own flags only; sizes the frame's buffers
// itself, so that no std::vector code is instantiated in an AVX2 compilation.
#include "raster/cpu/dispatch.hpp"

#include <fmt/format.h>

#include "raster/cpu/kernels.hpp"
#include "raster/cpu/variants.hpp"

namespace iesrgs::raster::cpu {

namespace {

template <typename T>
BlendPasses<T> passes([[maybe_unused]] Isa isa) {
#if defined(IESRGS_CPU_AVX2_VARIANT)
  if (isa == Isa::kAvx2) return avx2::blend_passes<T>();
#endif
  return baseline::blend_passes<T>();
}

}  // namespace

std::string describe_isa(Isa isa) {
  return fmt::format("{} ({}-byte packs)", cpu_isa::name(isa), passes<float>(isa).pack_bytes);
}

ProjectPacks active_project_packs() {
#if defined(IESRGS_CPU_AVX2_VARIANT)
  if (cpu_isa::active() == Isa::kAvx2) return avx2::project_packs();
#endif
  return baseline::project_packs();
}

template <typename T>
void blend_forward(RasterFrame<T>& frame, T* image, T* alpha, T* depth) {
  const size_t pixels = size_t(frame.camera.width) * frame.camera.height;
  frame.final_transmittance.resize(pixels);
  frame.contributors.resize(pixels);
  passes<T>(cpu_isa::active()).forward(frame, image, alpha, depth);
}

template <typename T>
void blend_backward(RasterFrame<T>& frame, const T* dimage, const T* dalpha, const T* ddepth) {
  frame.entry_grads.resize(frame.bins.entry_count());
  frame.splat_grads.resize(frame.splats.size());
  passes<T>(cpu_isa::active()).backward(frame, dimage, dalpha, ddepth);
}

template void blend_forward(RasterFrame<float>&, float*, float*, float*);
template void blend_forward(RasterFrame<double>&, double*, double*, double*);
template void blend_backward(RasterFrame<float>&, const float*, const float*, const float*);
template void blend_backward(RasterFrame<double>&, const double*, const double*, const double*);

}  // namespace iesrgs::raster::cpu
