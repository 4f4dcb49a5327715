// Chooses the instruction-set variant of the projection and blend passes, once per call. Compiled
// with the build's own flags only; sizes the frame's buffers itself, so that no std::vector code is
// instantiated in an AVX2 compilation.
#include <atomic>
#include <cstdlib>

#include "core/error.hpp"
#include "raster/cpu/dispatch.hpp"
#include "raster/cpu/kernels.hpp"
#include "raster/cpu/variants.hpp"

namespace iesrgs::raster::cpu {

namespace {

const char* isa_name(Isa isa) {
  return isa == Isa::kAvx2 ? "avx2" : "baseline";
}

bool cpu_runs_avx2_variant() {
#if defined(IESRGS_CPU_AVX2_VARIANT)
  // libgcc / compiler-rt also check that the OS saves the AVX registers.
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

void require_supported(Isa isa, const std::string& source) {
  if (!isa_supported(isa))
    fail("{}: the {} variant of the CPU kernels is not in this build or not supported by this CPU",
         source, isa_name(isa));
}

Isa initial_isa() {
  const char* name = std::getenv("IESRGS_CPU_ISA");
  if (!name || !*name) return isa_supported(Isa::kAvx2) ? Isa::kAvx2 : Isa::kBaseline;
  const Isa isa = parse_isa(name, "IESRGS_CPU_ISA");
  require_supported(isa, "IESRGS_CPU_ISA");
  return isa;
}

std::atomic<Isa>& active() {
  static std::atomic<Isa> isa{initial_isa()};
  return isa;
}

template <typename T>
BlendPasses<T> passes([[maybe_unused]] Isa isa) {
#if defined(IESRGS_CPU_AVX2_VARIANT)
  if (isa == Isa::kAvx2) return avx2::blend_passes<T>();
#endif
  return baseline::blend_passes<T>();
}

}  // namespace

Isa parse_isa(const std::string& name, const std::string& source) {
  for (const Isa isa : {Isa::kBaseline, Isa::kAvx2})
    if (name == isa_name(isa)) return isa;
  fail("{}: unknown instruction set '{}' (expected baseline or avx2)", source, name);
}

bool isa_supported(Isa isa) {
  return isa == Isa::kBaseline || cpu_runs_avx2_variant();
}

Isa active_isa() {
  return active().load(std::memory_order_relaxed);
}

void set_active_isa(Isa isa) {
  require_supported(isa, "set_active_isa");
  active().store(isa, std::memory_order_relaxed);
}

std::string describe_isa(Isa isa) {
  return fmt::format("{} ({}-byte packs)", isa_name(isa), passes<float>(isa).pack_bytes);
}

ProjectPacks active_project_packs() {
#if defined(IESRGS_CPU_AVX2_VARIANT)
  if (active_isa() == Isa::kAvx2) return avx2::project_packs();
#endif
  return baseline::project_packs();
}

template <typename T>
void blend_forward(RasterFrame<T>& frame, T* image, T* alpha, T* depth) {
  const size_t pixels = size_t(frame.camera.width) * frame.camera.height;
  frame.final_transmittance.resize(pixels);
  frame.contributors.resize(pixels);
  passes<T>(active_isa()).forward(frame, image, alpha, depth);
}

template <typename T>
void blend_backward(RasterFrame<T>& frame, const T* dimage, const T* dalpha, const T* ddepth) {
  frame.entry_grads.resize(frame.bins.entry_count());
  frame.splat_grads.resize(frame.splats.size());
  passes<T>(active_isa()).backward(frame, dimage, dalpha, ddepth);
}

template void blend_forward(RasterFrame<float>&, float*, float*, float*);
template void blend_forward(RasterFrame<double>&, double*, double*, double*);
template void blend_backward(RasterFrame<float>&, const float*, const float*, const float*);
template void blend_backward(RasterFrame<double>&, const double*, const double*, const double*);

}  // namespace iesrgs::raster::cpu
