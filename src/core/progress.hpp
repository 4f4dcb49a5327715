#pragma once
// Progress lines for long loops: durations and ETAs as people read them, and the pace of a loop
// over items (images upscaled, views of a stage).
#include <cstddef>
#include <cstdio>
#include <string>

#include "core/stopwatch.hpp"

namespace iesrgs {

// "1h02m05s", "3m07s", "42s".
std::string format_duration(double seconds);

// The time left for `total` items when `done` of them took `seconds`, at their mean pace.
std::string format_eta(size_t done, size_t total, double seconds);

// "<what> done/total" on stderr: rewritten in place on a terminal; in a log or a pipe, where a
// carriage return would pile the counts onto one line, only the last count, as a line.
void print_count_on_stderr(const char* what, size_t done, size_t total);

// Times a loop over `total` items, for its per-item progress lines.
class ItemPace {
 public:
  explicit ItemPace(size_t total) : total_(total) {}

  // When the `done`-th item has finished: the seconds it took and the ETA of the rest,
  // "0.42 s, ETA 1m03s".
  std::string finished(size_t done);

 private:
  size_t total_;
  Stopwatch all_, item_;
};

}  // namespace iesrgs
