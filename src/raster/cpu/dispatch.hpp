#pragma once
// The instruction-set variants (core/cpu_isa.hpp) of the CPU projection and blend passes.
#include <string>

#include "core/cpu_isa.hpp"

namespace iesrgs::raster::cpu {

using cpu_isa::Isa;

// The variant's name and the blend passes' vector width, e.g. "avx2 (32-byte packs)".
std::string describe_isa(Isa isa);

}  // namespace iesrgs::raster::cpu
