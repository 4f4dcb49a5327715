#include "core/memory.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "support/cuda_device.hpp"
#include "support/expect_error.hpp"

namespace iesrgs {
namespace {

using testing::contains;
using testing::error_message;

TEST(Memory, AvailableAndPeakAreReadOnLinux) {
  EXPECT_GT(available_memory_bytes(), 0);
  EXPECT_GT(peak_memory_bytes(), 0);
}

TEST(Memory, RequiringMoreThanIsAvailableNamesWhatNeedsIt) {
  EXPECT_NO_THROW(require_memory(1 << 20, "a small buffer"));
  const int64_t too_much = available_memory_bytes() + (int64_t(1) << 30);
  const std::string message = error_message([&] { require_memory(too_much, "a huge buffer"); });
  EXPECT_TRUE(contains(message, "not enough memory: a huge buffer needs about")) << message;
}

// MemAvailable from /proc/meminfo, in bytes, read here independently of the library.
int64_t mem_available_bytes() {
  std::ifstream in("/proc/meminfo");
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string key;
    int64_t kib = -1;
    if (fields >> key >> kib && key == "MemAvailable:") return kib * 1024;
  }
  return -1;
}

TEST(Memory, TheCpuByDefaultIsMemAvailable) {
  const int64_t expected = mem_available_bytes();
  ASSERT_GT(expected, 0) << "no MemAvailable in /proc/meminfo";
  // Other processes move it between the reads, by far less than a tenth.
  EXPECT_NEAR(double(available_memory_bytes(torch::kCPU)), double(expected), 0.1 * expected);
  EXPECT_NEAR(double(available_memory_bytes()), double(expected), 0.1 * expected);
}

TEST(Memory, GpuMemoryIsTheDevicesFreeMemory) {
  IESRGS_SKIP_WITHOUT_CUDA();
  const int64_t free = available_memory_bytes(torch::kCUDA);
  EXPECT_GT(free, 0);
  const std::string message = error_message(
      [&] { require_memory(free + (int64_t(1) << 30), "a huge model", torch::kCUDA); });
  EXPECT_TRUE(contains(message, "not enough GPU memory: a huge model needs about")) << message;
}

}  // namespace
}  // namespace iesrgs
