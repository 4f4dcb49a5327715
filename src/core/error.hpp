#pragma once
// One exception type for every user-facing failure. The CLI prints what() on one line and exits
// non-zero, so messages name the file and the problem ("path: problem") and never end in a newline.
#include <filesystem>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace iesrgs {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Work stopped by Ctrl-C or SIGTERM at a safe point: the CLI says so and exits with the shell's
// status for that signal (130 or 143), so scripts see that the run did not finish.
class Interrupted : public Error {
 public:
  using Error::Error;
};

// Throws Error("<path>: <problem>").
[[noreturn]] void fail_file(const std::filesystem::path& path, const std::string& problem);

template <typename... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
  throw Error(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace iesrgs
