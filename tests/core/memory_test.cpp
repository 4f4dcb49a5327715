#include "core/memory.hpp"

#include <gtest/gtest.h>

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

TEST(Memory, TheCpuIsTheDefaultDevice) {
  const int64_t cpu = available_memory_bytes(torch::kCPU);
  EXPECT_GT(cpu, 0);
  // MemAvailable moves with other processes; both reads fall in the same range.
  EXPECT_NEAR(double(cpu), double(available_memory_bytes()), 0.5 * double(cpu));
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
