#pragma once
// What a training run tells the person watching it (a line every couple of seconds: iteration,
// it/s, loss, Gaussians, ETA, test PSNR when measured) and the CSV log kept beside the outputs.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "core/stopwatch.hpp"

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
  // A row a full disk refused would reach the file later, in part or twice, among later rows:
  // training stops instead (its checkpoint stays, and --resume cuts the log back to it).
  void require_written() const;

  std::filesystem::path path_;
  std::ofstream csv_;
  int64_t first_iteration_, total_iterations_, log_every_;
  double seconds_before_;
  Stopwatch run_, since_print_;
  int64_t last_print_iteration_;
  double smoothed_loss_ = 0;
};

}  // namespace iesrgs::train
