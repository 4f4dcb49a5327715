#pragma once
// Runs work in a child process, for what a signal does to a whole process.
#include <sys/wait.h>
#include <unistd.h>

#include <functional>

namespace iesrgs::testing {

// The signal that ended a child process running `work`, 0 when it ended normally.
inline int ended_by(const std::function<void()>& work) {
  const pid_t child = ::fork();
  if (child == 0) {
    work();
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFSIGNALED(status) ? WTERMSIG(status) : 0;
}

}  // namespace iesrgs::testing
