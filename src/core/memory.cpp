#include "core/memory.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <optional>
#include <string>

#include "core/error.hpp"
#ifdef IESRGS_WITH_CUDA
#include "core/cuda/device.hpp"
#endif

namespace iesrgs {

namespace {

namespace fs = std::filesystem;

// The value of `key` in a /proc file of "key: value kB" lines, in bytes; -1 when absent.
int64_t proc_kib_field(const fs::path& file, const std::string& key) {
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

// The lesser of two amounts of memory, where -1 is one nobody states (no limit): -1 when neither
// is stated.
int64_t least_stated(int64_t a, int64_t b) {
  return a < 0 ? b : b < 0 ? a : std::min(a, b);
}

// The first number in `file`, -1 when there is none ("max", an absent file).
int64_t file_number(const fs::path& file) {
  std::ifstream in(file);
  int64_t value = -1;
  return in >> value ? value : -1;
}

// The value of `key` in a cgroup's memory.stat ("key value" lines, in bytes), 0 when absent.
int64_t stat_field(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  std::string name;
  int64_t value = 0;
  while (in >> name >> value)
    if (name == key) return value;
  return 0;
}

// The cgroup path of this process in one hierarchy of /proc/self/cgroup ("id:controllers:path"):
// v2's line has id 0 and no controllers, v1's memory hierarchy names "memory" among them.
std::optional<std::string> cgroup_path(const fs::path& proc_self, bool v2) {
  std::ifstream in(proc_self / "cgroup");
  for (std::string line; std::getline(in, line);) {
    const size_t first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = "," + line.substr(first + 1, second - first - 1) + ",";
    const bool match = v2 ? line.compare(0, first, "0") == 0 && controllers == ",,"
                          : controllers.find(",memory,") != std::string::npos;
    if (match) return line.substr(second + 1);
  }
  return std::nullopt;
}

// The files of a cgroup hierarchy's memory controller: v2's or v1's.
struct CgroupFiles {
  const char *limit, *usage, *inactive_file;
};

// The least memory left at any level of a cgroup hierarchy, from the process's group up to `root`
// (a container sees its own group as the root), -1 when no level sets a limit.
int64_t cgroup_memory_left(const fs::path& root, const std::string& path,
                           const CgroupFiles& names) {
  std::error_code ec;
  fs::path group = (root / fs::path(path).relative_path()).lexically_normal();
  if (!fs::is_directory(group, ec)) group = root;
  int64_t least = -1;
  constexpr int64_t kNoLimit = int64_t(1) << 60;  // v1 writes "no limit" as about 2^63
  for (fs::path level = group;; level = level.parent_path()) {
    const int64_t limit = file_number(level / names.limit);
    if (limit >= 0 && limit < kNoLimit) {
      const int64_t used =
          file_number(level / names.usage) - stat_field(level / "memory.stat", names.inactive_file);
      least = least_stated(least, std::max<int64_t>(0, limit - std::max<int64_t>(0, used)));
    }
    if (level == root || !level.has_relative_path() || level == level.parent_path()) break;
  }
  return least;
}

double gib(int64_t bytes) {
  return double(bytes) / double(int64_t(1) << 30);
}

// The process's peak before the last restart_peak_memory, which VmHWM no longer holds.
std::atomic<int64_t> peak_before_restart{0};

}  // namespace

int64_t recent_peak_memory_bytes() {
  return std::max<int64_t>(0, proc_kib_field("/proc/self/status", "VmHWM:"));
}

int64_t peak_memory_bytes() {
  return std::max(peak_before_restart.load(), recent_peak_memory_bytes());
}

int64_t resident_memory_bytes() {
  return std::max<int64_t>(0, proc_kib_field("/proc/self/status", "VmRSS:"));
}

void restart_peak_memory() {
  const int64_t peak = peak_memory_bytes();
  int64_t earlier = peak_before_restart.load();
  while (earlier < peak && !peak_before_restart.compare_exchange_weak(earlier, peak)) {
  }
  std::ofstream("/proc/self/clear_refs") << "5";  // resets VmHWM to VmRSS
}

int64_t limited_memory_bytes(const fs::path& cgroup_mount, const fs::path& proc_self) {
  int64_t least = -1;
  if (const auto path = cgroup_path(proc_self, true))
    least = least_stated(
        least,
        cgroup_memory_left(cgroup_mount, *path, {"memory.max", "memory.current", "inactive_file"}));
  if (const auto path = cgroup_path(proc_self, false))
    least = least_stated(
        least, cgroup_memory_left(
                   cgroup_mount / "memory", *path,
                   {"memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file"}));
  rlimit address_space{};
  if (::getrlimit(RLIMIT_AS, &address_space) == 0 && address_space.rlim_cur != RLIM_INFINITY) {
    const int64_t mapped = proc_kib_field(proc_self / "status", "VmSize:");
    if (mapped >= 0)
      least = least_stated(least, std::max<int64_t>(0, int64_t(address_space.rlim_cur) - mapped));
  }
  return least;
}

int64_t available_memory_bytes(torch::Device device) {
  if (device.is_cpu())
    return least_stated(proc_kib_field("/proc/meminfo", "MemAvailable:"), limited_memory_bytes());
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
