#pragma once
#include <cstdint>

namespace iesrgs {

// Peak resident memory of this process so far (VmHWM), in bytes; 0 where the OS does not say.
int64_t peak_memory_bytes();

}  // namespace iesrgs
