#pragma once
#include <cstdint>
#include <string>

namespace iesrgs {

// Peak resident memory of this process so far (VmHWM), in bytes; 0 where the OS does not say.
int64_t peak_memory_bytes();

// What new allocations can get without swapping (MemAvailable), in bytes; -1 where the OS does not
// say.
int64_t available_memory_bytes();

// Throws Error when `bytes` is more than the available memory, saying that `what` needs them.
// Linux overcommits: a too-large allocation usually succeeds, and the kernel kills the process
// later, when it touches the pages; this check turns that into an error before the work starts.
void require_memory(int64_t bytes, const std::string& what);

}  // namespace iesrgs
