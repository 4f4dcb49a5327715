#include "core/progress.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace iesrgs {

std::string format_duration(double seconds) {
  const int64_t total = std::llround(std::max(0.0, seconds));
  const int64_t h = total / 3600, m = total / 60 % 60, s = total % 60;
  if (h > 0) return fmt::format("{}h{:02}m{:02}s", h, m, s);
  if (m > 0) return fmt::format("{}m{:02}s", m, s);
  return fmt::format("{}s", s);
}

std::string format_eta(size_t done, size_t total, double seconds) {
  if (done == 0) return "?";
  return format_duration(seconds / double(done) * double(total - std::min(done, total)));
}

void print_count_on_stderr(const char* what, size_t done, size_t total) {
  static const bool terminal = isatty(fileno(stderr));
  if (terminal)
    fmt::print(stderr, "\r{} {}/{}{}", what, done, total, done == total ? "\n" : "");
  else if (done == total)
    fmt::print(stderr, "{} {}/{}\n", what, done, total);
}

std::string ItemPace::finished(size_t done) {
  return fmt::format("{:.2f} s, ETA {}", item_.lap(), format_eta(done, total_, all_.seconds()));
}

}  // namespace iesrgs
