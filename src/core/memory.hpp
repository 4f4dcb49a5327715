#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include <torch/types.h>

namespace iesrgs {

// Peak resident memory of this process so far (VmHWM), in bytes; 0 where the OS does not say.
int64_t peak_memory_bytes();

// Resident memory of this process now (VmRSS), in bytes; 0 where the OS does not say.
int64_t resident_memory_bytes();

// Starts recent_peak_memory_bytes afresh from the present resident memory (Linux's clear_refs),
// so that it measures one piece of work, not the process's earlier ones.
void restart_peak_memory();

// Peak resident memory since restart_peak_memory (the process's peak where the OS does not allow
// a restart, or before any), in bytes; 0 where the OS does not say.
int64_t recent_peak_memory_bytes();

// What new allocations on `device` can get, in bytes: on the CPU without swapping (MemAvailable,
// or less where limited_memory_bytes says so), on a GPU its free memory; -1 where neither the OS
// nor the device says.
int64_t available_memory_bytes(torch::Device device = torch::kCPU);

// What this process may still allocate under the limits Linux sets besides the machine's memory:
// its cgroup's (a container's or a systemd unit's: v2 memory.max or v1 memory.limit_in_bytes, at
// every level up to the hierarchy's root, less what the group uses beyond its reclaimable file
// cache) and its address space's (ulimit -v, less what it maps). -1 where neither limits it.
// The paths are those of the cgroup file systems and of /proc/self, for tests to replace.
int64_t limited_memory_bytes(const std::filesystem::path& cgroup_mount = "/sys/fs/cgroup",
                             const std::filesystem::path& proc_self = "/proc/self");

// Throws Error when `bytes` is more than the available memory of `device`, saying that `what`
// needs them. Linux overcommits: a too-large allocation usually succeeds, and the kernel kills the
// process later, when it touches the pages; this check turns that into an error before the work
// starts.
void require_memory(int64_t bytes, const std::string& what, torch::Device device = torch::kCPU);

}  // namespace iesrgs
