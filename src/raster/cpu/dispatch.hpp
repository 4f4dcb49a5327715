#pragma once
// How an instruction-set variant (core/cpu_isa.hpp) of the CPU kernels is described in reports;
// dispatch.cpp runs the active one.
#include <string>

#include "core/cpu_isa.hpp"

namespace iesrgs::raster::cpu {

using cpu_isa::Isa;

// The variant's name and the blend passes' vector width, e.g. "avx2 (32-byte packs)".
std::string describe_isa(Isa isa);

}  // namespace iesrgs::raster::cpu
