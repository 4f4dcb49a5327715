#pragma once
// Run-time choice of the instruction-set variant (isa.hpp) of the CPU projection and blend passes.
#include <string>

namespace iesrgs::raster::cpu {

enum class Isa {
  kBaseline,  // the build's own flags: SSE2 when portable, the build machine's with IESRGS_NATIVE
  kAvx2,      // AVX2 and FMA; only in optimized portable builds for x86
};

// Parses an instruction-set name ("baseline" or "avx2"); throws Error naming `source` otherwise.
Isa parse_isa(const std::string& name, const std::string& source);
// Whether this build has the variant and this CPU can run it.
bool isa_supported(Isa isa);
// The variant that later passes run: at first the best supported one, or the one that the
// environment variable IESRGS_CPU_ISA names (throws Error where it is unknown or unsupported).
Isa active_isa();
// Makes later passes, in every thread, run `isa`; throws Error where it is unsupported.
void set_active_isa(Isa isa);
// The variant's name and vector width, e.g. "avx2 (32-byte packs)".
std::string describe_isa(Isa isa);

}  // namespace iesrgs::raster::cpu
