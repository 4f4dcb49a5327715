#include "train/progress.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "support/child_process.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::train {
namespace {

std::vector<std::string> lines_of(const std::filesystem::path& file) {
  std::vector<std::string> lines;
  std::istringstream in(read_file(file));
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// A resumed run continues the log at its checkpoint: rows written after it, or cut off by a
// killed process, go; the training time goes on from the checkpoint's.
TEST(TrainProgress, AResumedLogContinuesFromItsCheckpoint) {
  testing::TempDir dir;
  const auto csv = dir / "train_log.csv";
  write_file_atomically(csv,
                        "iteration,loss,gaussians,elapsed_seconds,test_psnr\n"
                        "1,0.5,10,0.1,\n2,0.4,10,0.2,\n3,0.3,10,0.3,\n4,0.2,1");
  {
    ProgressLog log(csv, 2, 10, 1, 5.0);
    log.record(3, 0.25, 12, std::nullopt, false);
  }
  const std::vector<std::string> resumed = lines_of(csv);
  ASSERT_EQ(resumed.size(), 4u);
  EXPECT_EQ(resumed[2], "2,0.4,10,0.2,");
  EXPECT_EQ(resumed[3].rfind("3,0.25,12,", 0), 0u) << resumed[3];
  EXPECT_GE(std::stod(resumed[3].substr(std::string("3,0.25,12,").size())), 5.0);

  { ProgressLog fresh(csv, 0, 10, 1, 0.0); }  // a new run starts the log again
  EXPECT_EQ(lines_of(csv).size(), 1u);
}

// Rows every log_every iterations, and whenever a test PSNR comes in or the caller forces one.
TEST(TrainProgress, LogsEveryLogEveryIterations) {
  testing::TempDir dir;
  const auto csv = dir / "train_log.csv";
  {
    ProgressLog log(csv, 0, 12, 5, 0.0);
    for (int64_t i = 1; i <= 12; ++i)
      log.record(i, 0.5, 10, i == 7 ? std::optional<double>(20.0) : std::nullopt, i == 12);
  }
  std::vector<int> iterations;
  for (const std::string& row : lines_of(csv)) iterations.push_back(std::atoi(row.c_str()));
  EXPECT_EQ(iterations, (std::vector<int>{0, 5, 7, 10, 12}));  // the header reads as 0
}

// Logs rows until the disk refuses one: 0 when that stops the training naming the log, 2 for
// another error, 3 for none.
int log_until_the_disk_is_full(const std::filesystem::path& csv) {
  try {
    ProgressLog log(csv, 0, 100000, 1, 0.0);
    for (int64_t i = 1; i <= 100000; ++i) log.record(i, 0.5, 10, std::nullopt, false);
  } catch (const Error& e) {
    return testing::contains(e.what(), csv.string() + ": write failed: File too large") ? 0 : 2;
  }
  return 3;
}

// A row the disk refuses would reach the file later, in part or twice: the training stops there.
TEST(TrainProgress, ARowTheDiskRefusesStopsTheTraining) {
  testing::TempDir dir;
  const auto csv = dir / "train_log.csv";
  EXPECT_EQ(testing::exit_status_with_file_size_limit(
                4096, [&] { return log_until_the_disk_is_full(csv); }),
            0);
}

}  // namespace
}  // namespace iesrgs::train
