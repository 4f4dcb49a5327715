#pragma once
// Runs the built iesrgs binary as a user would, for end-to-end tests of the CLI.
#include <string>

#include "support/expect_error.hpp"  // contains, for checking the output

namespace iesrgs::testing {

struct CliRun {
  int status = -1;
  std::string output;  // stdout and stderr together
};

// `args` is appended to the binary's path and run by the shell.
CliRun iesrgs(const std::string& args);

// The last line of the output: where the CLI puts its one-line error.
std::string last_line(const std::string& output);

}  // namespace iesrgs::testing
