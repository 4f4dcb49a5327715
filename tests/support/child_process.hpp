#pragma once
// Runs work in a child process, so that what it does to its process (a resource limit, a crash)
// ends with it. The child runs one thread: `work` must not start OpenMP or LibTorch work.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <functional>
#include <string>

namespace iesrgs::testing {

// waitpid's status of a child process running `work`, which exits with work's return value.
inline int wait_status_of_child(const std::function<int()>& work) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(work());
  int status = 0;
  ::waitpid(child, &status, 0);
  return status;
}

// The exit status of a child process running `work` (its return value), -1 when it did not exit.
inline int exit_status_in_child(const std::function<int()>& work) {
  const int status = wait_status_of_child(work);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The signal that ended a child process running `work`, 0 when it ended normally.
inline int ended_by(const std::function<void()>& work) {
  const int status = wait_status_of_child([&] {
    work();
    return 0;
  });
  return WIFSIGNALED(status) ? WTERMSIG(status) : 0;
}

// The same in a child whose files cannot grow past `bytes`, as on a disk that is full: a write
// beyond it fails with EFBIG ("File too large").
inline int exit_status_with_file_size_limit(rlim_t bytes, const std::function<int()>& work) {
  return exit_status_in_child([&] {
    std::signal(SIGXFSZ, SIG_IGN);  // the write fails instead of the signal ending the process
    const rlimit limit{bytes, bytes};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    return work();
  });
}

// The same in a child that can map only `bytes` more than it has mapped already: an allocation
// beyond that fails, as when the machine's memory runs out.
inline int exit_status_with_memory_to_spare(rlim_t bytes, const std::function<int()>& work) {
  return exit_status_in_child([&] {
    std::ifstream status("/proc/self/status");
    rlim_t mapped_kib = 0;
    for (std::string key; status >> key;)
      if (key == "VmSize:" && status >> mapped_kib) break;
    const rlimit limit{mapped_kib * 1024 + bytes, mapped_kib * 1024 + bytes};
    ::setrlimit(RLIMIT_AS, &limit);
    return work();
  });
}

}  // namespace iesrgs::testing
