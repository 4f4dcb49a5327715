#pragma once
// CUDA status checks.
#include <cuda_runtime.h>

#include "core/error.hpp"

namespace iesrgs::cuda {

// Throws Error naming the failed operation and CUDA's message (e.g. "out of memory").
inline void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) fail("CUDA: {} failed: {}", what, cudaGetErrorString(status));
}

}  // namespace iesrgs::cuda
