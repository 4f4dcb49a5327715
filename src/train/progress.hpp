#pragma once
// What a training run tells the person watching it (a line every couple of seconds: iteration,
// it/s, loss, Gaussians, ETA, test PSNR when measured) and the CSV log kept beside the outputs.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

namespace iesrgs::train {

class ProgressLog {
 public:
  // Starts `csv` afresh, or, for a run resumed after `first_iteration` that had trained for
  // `seconds_before`, continues it after that iteration: rows logged after the checkpoint, or cut
  // off by a killed process, are dropped first.
  ProgressLog(const std::filesystem::path& csv, int64_t first_iteration, int64_t total_iterations,
              int64_t log_every, double seconds_before);

  // Logs a row every `log_every` iterations, and prints a line, when `force` or a test PSNR came
  // in; prints also when enough time has passed.
  void record(int64_t iteration, double loss, int64_t gaussians, std::optional<double> test_psnr,
              bool force);

  // Writes the rows recorded so far: those up to a checkpoint's iteration are then in the file.
  void flush();

 private:
  using Clock = std::chrono::steady_clock;
  std::ofstream csv_;
  int64_t first_iteration_, total_iterations_, log_every_;
  double seconds_before_;
  Clock::time_point start_, last_print_;
  int64_t last_print_iteration_;
  double smoothed_loss_ = 0;
};

// "1h02m05s", "3m07s", "42s".
std::string format_duration(double seconds);

// The time left for `total` items when `done` of them took `seconds`, at their mean pace.
std::string format_eta(size_t done, size_t total, double seconds);

// Times a loop over `total` items, for its per-item progress lines.
class ItemPace {
 public:
  explicit ItemPace(size_t total);

  // When the `done`-th item has finished: the seconds it took and the ETA of the rest,
  // "0.42 s, ETA 1m03s".
  std::string finished(size_t done);

 private:
  using Clock = std::chrono::steady_clock;
  size_t total_;
  Clock::time_point first_, last_;
};

}  // namespace iesrgs::train
