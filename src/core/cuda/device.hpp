#pragma once
// Whether, and which, CUDA device this process can use.
#include <cuda_runtime.h>

#include <cstdint>
#include <string>

#include "core/cuda/check.hpp"

namespace iesrgs::cuda {

// False without a GPU or a driver: the CUDA tests skip, the CUDA benchmark stops.
inline bool device_available() {
  int count = 0;
  return cudaGetDeviceCount(&count) == cudaSuccess && count > 0;
}

// The current device's name and compute capability, e.g. "NVIDIA H100 80GB HBM3 (sm_90)".
inline std::string device_description() {
  int device = 0;
  check(cudaGetDevice(&device), "cudaGetDevice");
  cudaDeviceProp prop;
  check(cudaGetDeviceProperties(&prop, device), "cudaGetDeviceProperties");
  return fmt::format("{} (sm_{}{})", prop.name, prop.major, prop.minor);
}

// Free memory on the current device, in bytes; -1 when CUDA cannot say. LibTorch's allocator
// keeps freed blocks for reuse, and they count as used here: what is left is what growth beyond
// the present peak can get.
inline int64_t free_memory_bytes() {
  size_t free = 0, total = 0;
  if (cudaMemGetInfo(&free, &total) == cudaSuccess) return int64_t(free);
  cudaGetLastError();  // a query's failure must not fail the next launch
  return -1;
}

}  // namespace iesrgs::cuda
