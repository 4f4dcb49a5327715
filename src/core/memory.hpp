#pragma once
#include <cstdint>
#include <string>

#include <torch/types.h>

namespace iesrgs {

// Peak resident memory of this process so far (VmHWM), in bytes; 0 where the OS does not say.
int64_t peak_memory_bytes();

// What new allocations on `device` can get, in bytes: on the CPU without swapping (MemAvailable),
// on a GPU its free memory; -1 where neither the OS nor the device says.
int64_t available_memory_bytes(torch::Device device = torch::kCPU);

// Throws Error when `bytes` is more than the available memory of `device`, saying that `what`
// needs them. Linux overcommits: a too-large allocation usually succeeds, and the kernel kills the
// process later, when it touches the pages; this check turns that into an error before the work
// starts.
void require_memory(int64_t bytes, const std::string& what, torch::Device device = torch::kCPU);

}  // namespace iesrgs
