#include "core/memory.hpp"

#include <algorithm>
#include <fstream>
#include <string>

#include "core/error.hpp"
#ifdef IESRGS_WITH_CUDA
#include "core/cuda/device.hpp"
#endif

namespace iesrgs {

namespace {

// The value of `key` in a /proc file of "key: value kB" lines, in bytes; -1 when absent.
int64_t proc_kib_field(const char* file, const std::string& key) {
  std::ifstream status(file);
  std::string name;
  while (status >> name) {
    if (name == key) {
      int64_t kib = 0;
      status >> kib;
      return kib * 1024;
    }
    status.ignore(1 << 16, '\n');
  }
  return -1;
}

double gib(int64_t bytes) {
  return double(bytes) / double(int64_t(1) << 30);
}

}  // namespace

int64_t peak_memory_bytes() {
  return std::max<int64_t>(0, proc_kib_field("/proc/self/status", "VmHWM:"));
}

int64_t available_memory_bytes(torch::Device device) {
  if (device.is_cpu()) return proc_kib_field("/proc/meminfo", "MemAvailable:");
#ifdef IESRGS_WITH_CUDA
  if (device.is_cuda()) return cuda::free_memory_bytes();
#endif
  return -1;
}

void require_memory(int64_t bytes, const std::string& what, torch::Device device) {
  const int64_t available = available_memory_bytes(device);
  if (available >= 0 && bytes > available)
    fail("not enough {}memory: {} needs about {:.1f} GiB, and {:.1f} GiB is available",
         device.is_cpu() ? "" : "GPU ", what, gib(bytes), gib(available));
}

}  // namespace iesrgs
