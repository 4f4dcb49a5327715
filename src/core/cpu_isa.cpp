#include "core/cpu_isa.hpp"

#include <atomic>
#include <cstdlib>

#include "core/error.hpp"

namespace iesrgs::cpu_isa {
namespace {

bool cpu_runs_avx2_variant() {
#if defined(IESRGS_CPU_AVX2_VARIANT)
  // libgcc / compiler-rt also check that the OS saves the AVX registers.
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

void require_supported(Isa isa, const std::string& source) {
  if (!supported(isa))
    fail("{}: the {} variant of the CPU kernels is not in this build or not supported by this CPU",
         source, name(isa));
}

Isa initial() {
  const char* chosen = std::getenv("IESRGS_CPU_ISA");
  if (!chosen || !*chosen) return supported(Isa::kAvx2) ? Isa::kAvx2 : Isa::kBaseline;
  const Isa isa = parse(chosen, "IESRGS_CPU_ISA");
  require_supported(isa, "IESRGS_CPU_ISA");
  return isa;
}

std::atomic<Isa>& current() {
  static std::atomic<Isa> isa{initial()};
  return isa;
}

}  // namespace

const char* name(Isa isa) {
  return isa == Isa::kAvx2 ? "avx2" : "baseline";
}

Isa parse(const std::string& text, const std::string& source) {
  for (const Isa isa : {Isa::kBaseline, Isa::kAvx2})
    if (text == name(isa)) return isa;
  fail("{}: unknown instruction set '{}' (expected baseline or avx2)", source, text);
}

bool supported(Isa isa) {
  return isa == Isa::kBaseline || cpu_runs_avx2_variant();
}

Isa active() {
  return current().load(std::memory_order_relaxed);
}

void set_active(Isa isa) {
  require_supported(isa, "cpu_isa::set_active");
  current().store(isa, std::memory_order_relaxed);
}

}  // namespace iesrgs::cpu_isa
