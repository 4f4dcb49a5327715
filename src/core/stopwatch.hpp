#pragma once
// Wall time since a start, on the steady clock: what progress lines, stage records and
// benchmarks report.
#include <chrono>

namespace iesrgs {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}

  void restart() { start_ = std::chrono::steady_clock::now(); }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  double milliseconds() const { return 1e3 * seconds(); }
  // Seconds since the start or the previous lap, which starts the next.
  double lap() {
    const double s = seconds();
    restart();
    return s;
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace iesrgs
