#pragma once
// Runs work in a child process whose files cannot grow past a limit, as on a disk that is full:
// a write beyond it fails with EFBIG ("File too large").
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <functional>

namespace iesrgs::testing {

// The exit status of a child process running `work` (its return value), -1 when it did not exit.
inline int exit_status_with_file_size_limit(rlim_t bytes, const std::function<int()>& work) {
  const pid_t child = ::fork();
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // the write fails instead of the signal ending the process
    const rlimit limit{bytes, bytes};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    ::_exit(work());
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace iesrgs::testing
