#include "core/memory.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/child_process.hpp"
#include "support/cuda_device.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

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

// One piece of work's peak, apart from the process's: a training's, after an earlier row's.
TEST(Memory, APeakRestartsForOnePieceOfWorkAndTheProcesssStays) {
  {
    std::vector<char> touched(size_t(256) << 20, 1);  // resident while it lives
    EXPECT_GE(recent_peak_memory_bytes(), resident_memory_bytes());
    EXPECT_GE(recent_peak_memory_bytes(), int64_t(touched.size()));
  }
  const int64_t lifetime = peak_memory_bytes();
  restart_peak_memory();
  EXPECT_GE(peak_memory_bytes(), lifetime);
  EXPECT_LE(recent_peak_memory_bytes(), lifetime);
#if !defined(__SANITIZE_ADDRESS__)  // whose allocator keeps freed memory in quarantine
  EXPECT_LT(recent_peak_memory_bytes(), lifetime - (int64_t(128) << 20));
#endif
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

TEST(Memory, TheCpuByDefaultIsMemAvailableOrTheLimitBelowIt) {
  const int64_t machine = mem_available_bytes();
  ASSERT_GT(machine, 0) << "no MemAvailable in /proc/meminfo";
  const int64_t limited = limited_memory_bytes();
  const int64_t expected = limited >= 0 ? std::min(machine, limited) : machine;
  // Other processes move it between the reads, by far less than a tenth.
  EXPECT_NEAR(double(available_memory_bytes(torch::kCPU)), double(expected), 0.1 * expected);
  EXPECT_NEAR(double(available_memory_bytes()), double(expected), 0.1 * expected);
}

// A cgroup's limit, as a container or a systemd unit sets it: what its group may still take,
// counting its reclaimable file cache as free, and the least of its levels'.
TEST(Memory, ACgroupsLimitIsWhatIsLeftBelowIt) {
  testing::TempDir dir;
  const auto write = [&](const std::filesystem::path& file, const std::string& text) {
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file) << text;
  };
  constexpr int64_t kMiB = 1 << 20;
  // v2: the unit's own limit, and its parent's, which leaves less.
  write(dir / "proc" / "cgroup", "0::/outer/unit\n");
  write(dir / "cg" / "outer" / "unit" / "memory.max", std::to_string(800 * kMiB) + "\n");
  write(dir / "cg" / "outer" / "unit" / "memory.current", std::to_string(300 * kMiB) + "\n");
  write(dir / "cg" / "outer" / "unit" / "memory.stat",
        "anon 1\nfile 2\ninactive_file " + std::to_string(100 * kMiB) + "\n");
  EXPECT_EQ(limited_memory_bytes(dir / "cg", dir / "proc"), 600 * kMiB);
  write(dir / "cg" / "outer" / "memory.max", std::to_string(500 * kMiB) + "\n");
  write(dir / "cg" / "outer" / "memory.current", std::to_string(400 * kMiB) + "\n");
  EXPECT_EQ(limited_memory_bytes(dir / "cg", dir / "proc"), 100 * kMiB);
  write(dir / "cg" / "outer" / "memory.max", "max\n");
  write(dir / "cg" / "outer" / "unit" / "memory.max", "max\n");
  EXPECT_EQ(limited_memory_bytes(dir / "cg", dir / "proc"), -1);

  // v1, seen from inside a container: its group is the hierarchy's root.
  write(dir / "proc" / "cgroup", "4:memory:/docker/abc\n0::/\n");
  write(dir / "cg" / "memory" / "memory.limit_in_bytes", std::to_string(2048 * kMiB) + "\n");
  write(dir / "cg" / "memory" / "memory.usage_in_bytes", std::to_string(1024 * kMiB) + "\n");
  write(dir / "cg" / "memory" / "memory.stat",
        "cache 1\ntotal_inactive_file " + std::to_string(24 * kMiB) + "\n");
  EXPECT_EQ(limited_memory_bytes(dir / "cg", dir / "proc"), 1048 * kMiB);
  write(dir / "cg" / "memory" / "memory.limit_in_bytes", "9223372036854771712\n");
  EXPECT_EQ(limited_memory_bytes(dir / "cg", dir / "proc"), -1);
}

// ulimit -v: what is left of the address space.
TEST(Memory, AnAddressSpaceLimitIsWhatIsLeftBelowIt) {
  EXPECT_EQ(testing::exit_status_with_memory_to_spare(
                64 << 20,
                [] {
                  const int64_t left = available_memory_bytes();
                  return left > (48 << 20) && left <= (64 << 20) ? 0 : 1;
                }),
            0);
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
