#pragma once
// Instruction-set variants of the CPU kernels. A portable x86-64 build compiles their hot loops
// twice (the files CMakeLists.txt lists for it), with its own flags (SSE2) and with -mavx2 -mfma
// (IESRGS_CPU_ISA_AVX2 defined), and cpu_isa.hpp picks one at run time. Each compilation defines
// everything of its own, inline and template functions included, in the namespace
// IESRGS_CPU_ISA_NAMESPACE: were a function of the AVX2 compilation to share its name with one of
// the baseline, the linker could keep the AVX2 copy for both, and the baseline path would fault on
// CPUs without AVX2. Functions of other headers (the standard library's, raster/*.hpp) must be
// inlined there, or take a type of the variant's namespace (the projection's lanes.hpp), so the
// variant is only built when optimizing, and the build checks the AVX2 object's symbols
// (check_isa_symbols.cmake).

#if defined(IESRGS_CPU_ISA_AVX2)
#if !defined(__AVX2__) || !defined(__FMA__)
#error "the avx2 variant of the CPU kernels must be compiled with -mavx2 -mfma"
#endif
#define IESRGS_CPU_ISA_NAMESPACE avx2
#else
#define IESRGS_CPU_ISA_NAMESPACE baseline
#endif
