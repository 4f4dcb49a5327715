#pragma once
// Run-time choice of the instruction-set variant (cpu_isa_variant.hpp) that the CPU kernels run.
#include <string>

namespace iesrgs::cpu_isa {

enum class Isa {
  kBaseline,  // the build's own flags: SSE2 when portable, the build machine's with IESRGS_NATIVE
  kAvx2,      // AVX2 and FMA; only in optimized portable builds for x86
};

// "baseline" or "avx2".
const char* name(Isa isa);
// Parses an instruction-set name; throws Error naming `source` otherwise.
Isa parse(const std::string& name, const std::string& source);
// Whether this build has the variant and this CPU can run it.
bool supported(Isa isa);
// The variant that later kernels run: at first the best supported one, or the one that the
// environment variable IESRGS_CPU_ISA names (throws Error where it is unknown or unsupported).
Isa active();
// Makes later kernels, in every thread, run `isa`; throws Error where it is unsupported.
void set_active(Isa isa);

}  // namespace iesrgs::cpu_isa
