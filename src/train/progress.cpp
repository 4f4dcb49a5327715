#include "train/progress.hpp"

#include <fmt/core.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>

#include "core/error.hpp"
#include "core/progress.hpp"
#include "io/atomic_file.hpp"

namespace iesrgs::train {

namespace {
constexpr double kPrintSeconds = 2.0;
constexpr double kLossSmoothing = 0.9;  // exponential moving average, as 3DGS's progress bar
constexpr const char* kHeader = "iteration,loss,gaussians,elapsed_seconds,test_psnr\n";

// The log of a run resumed after `last_iteration`: its header and the complete rows up to that
// iteration.
std::string log_until(const std::filesystem::path& csv, int64_t last_iteration) {
  std::string kept = kHeader;
  std::ifstream in(csv);
  std::string row;
  std::getline(in, row);  // the header
  while (std::getline(in, row)) {
    if (in.eof()) break;  // no newline: cut off by a killed process
    char* end = nullptr;
    const long long iteration = std::strtoll(row.c_str(), &end, 10);
    if (end == row.c_str() || *end != ',' || iteration > last_iteration) break;
    kept += row + '\n';
  }
  return kept;
}
}  // namespace

ProgressLog::ProgressLog(const std::filesystem::path& csv, int64_t first_iteration,
                         int64_t total_iterations, int64_t log_every, double seconds_before)
    : path_(csv),
      first_iteration_(first_iteration),
      total_iterations_(total_iterations),
      log_every_(log_every),
      seconds_before_(seconds_before),
      last_print_iteration_(first_iteration) {
  if (!csv.parent_path().empty()) std::filesystem::create_directories(csv.parent_path());
  write_file_atomically(csv, first_iteration > 0 ? log_until(csv, first_iteration) : kHeader);
  csv_.open(csv, std::ios::app);
  if (!csv_) fail_file(csv, "cannot be opened for writing");
}

void ProgressLog::flush() {
  errno = 0;
  csv_.flush();
  require_written();
}

void ProgressLog::require_written() const {
  if (!csv_) fail_file(path_, write_failure(errno));
}

void ProgressLog::record(int64_t iteration, double loss, int64_t gaussians,
                         std::optional<double> test_psnr, bool force) {
  smoothed_loss_ = iteration == first_iteration_ + 1
                       ? loss
                       : kLossSmoothing * smoothed_loss_ + (1 - kLossSmoothing) * loss;
  const double elapsed = run_.seconds();
  if (force || test_psnr || iteration % log_every_ == 0) {
    errno = 0;
    csv_ << iteration << ',' << loss << ',' << gaussians << ',' << seconds_before_ + elapsed << ',';
    if (test_psnr) csv_ << *test_psnr;
    csv_ << '\n';
    require_written();
  }
  const double since_print = since_print_.seconds();
  if (!force && !test_psnr && since_print < kPrintSeconds) return;
  since_print_.restart();
  flush();
  const double rate = since_print > 0 ? double(iteration - last_print_iteration_) / since_print : 0;
  std::string line = fmt::format(
      "[{:>{}}/{}] {:5.1f}% | {:6.2f} it/s | loss {:.4f} | {:>8} Gaussians | elapsed {} | ETA {}",
      iteration, std::to_string(total_iterations_).size(), total_iterations_,
      100.0 * double(iteration) / double(total_iterations_), rate, smoothed_loss_, gaussians,
      format_duration(elapsed),
      format_eta(size_t(iteration - first_iteration_), size_t(total_iterations_ - first_iteration_),
                 elapsed));
  if (test_psnr) line += fmt::format(" | test PSNR {:.2f} dB", *test_psnr);
  fmt::print("{}\n", line);
  std::fflush(stdout);
  last_print_iteration_ = iteration;
}

}  // namespace iesrgs::train
