#include "io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>

#include "core/interrupt.hpp"
#include "support/child_process.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::TempDir;

namespace fs = std::filesystem;

// What the signal handler removes: the temporary being written, under its own name. A write that
// fails leaves neither it nor the folders made for it.
TEST(AtomicFile, TheTemporaryBeingWrittenIsListedForRemoval) {
  TempDir dir;
  fs::path written;
  EXPECT_ANY_THROW(write_atomically(dir / "new" / "out.ply", [&](const fs::path& tmp) {
    std::ofstream(tmp) << "half";
    written = tmp;
    remove_temporaries_in_progress();
    EXPECT_FALSE(fs::exists(tmp));
    throw std::runtime_error("stop");
  }));
  EXPECT_NE(written.filename().string().find("out.ply.tmp-"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "new"));
  write_file_atomically(dir / "done.json", "{}");
  remove_temporaries_in_progress();  // nothing is in progress: finished files stay
  EXPECT_TRUE(fs::exists(dir / "done.json"));
}

// 0 when 8 KB written to `file` past a 4 KB limit fail naming it, as the system names the cause.
int write_past_the_limit(const fs::path& file) {
  const std::string message =
      testing::error_message([&] { write_file_atomically(file, std::string(8192, 'x')); });
  return testing::contains(message, file.string() + ": write failed: File too large") ? 0 : 1;
}

// A full disk is named as the system names it, and leaves no temporary.
TEST(AtomicFile, AFullDiskIsNamedAndLeavesNoTemporary) {
  TempDir dir;
  EXPECT_EQ(testing::exit_status_with_file_size_limit(
                4096, [&] { return write_past_the_limit(dir / "big.json"); }),
            0);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// Files that belong together are all written, or (here the second's temporary cannot be made)
// none of them.
TEST(AtomicFile, FilesThatBelongTogetherAreWrittenAllOrNone) {
  TempDir dir;
  const std::vector<std::pair<fs::path, std::string>> files = {
      {dir / "a.json", "a"}, {dir / "b.csv", "b"}, {dir / "c.md", "c"}};
  fs::create_directories(dir / ("b.csv.tmp-" + std::to_string(::getpid())) / "in-the-way");
  EXPECT_ANY_THROW(write_files_atomically(files));
  for (const auto& [path, bytes] : files) EXPECT_FALSE(fs::exists(path)) << path;
  fs::remove_all(dir / ("b.csv.tmp-" + std::to_string(::getpid())));
  // A rename that fails (a folder holds the name) takes back the files renamed before it, unless
  // they replaced an earlier output, which a removal would not bring back.
  fs::create_directories(dir / "b.csv" / "in-the-way");
  EXPECT_ANY_THROW(write_files_atomically(files));
  EXPECT_FALSE(fs::exists(dir / "a.json"));
  write_file_atomically(dir / "a.json", "earlier");
  EXPECT_ANY_THROW(write_files_atomically(files));
  EXPECT_EQ(read_file(dir / "a.json"), "a");
  fs::remove_all(dir / "b.csv");
  write_files_atomically(files);
  for (const auto& [path, bytes] : files) EXPECT_EQ(read_file(path), bytes);
}

// An earlier output that is not there is not blamed for what stands in the new one's way.
TEST(AtomicFile, AnEarlierOutputNotThereIsNotRemoved) {
  TempDir dir;
  std::ofstream(dir / "file") << "x";
  EXPECT_FALSE(remove_earlier_output(dir / "file" / "m.json", "left by an earlier eval"));
  EXPECT_FALSE(remove_earlier_output(dir / "absent.json", "left by an earlier eval"));
  EXPECT_TRUE(remove_earlier_output(dir / "file", "left by an earlier eval"));
  const std::string message = testing::error_message([&] {
    write_file_atomically(dir / "new" / "m.json", "{}");
    std::ofstream(dir / "blocker") << "x";
    write_file_atomically(dir / "blocker" / "m.json", "{}");
  });
  EXPECT_TRUE(testing::contains(message, (dir / "blocker").string() + ": cannot create the folder"))
      << message;
}

// Only the folders a write made go when it fails: here the parent it made before a name too long
// to make, and never a link to nothing that stands where a folder should be.
TEST(AtomicFile, AFailedWriteRemovesOnlyTheFoldersItMade) {
  TempDir dir;
  EXPECT_ANY_THROW(write_file_atomically(dir / "new" / std::string(300, 'x') / "m.json", "{}"));
  EXPECT_FALSE(fs::exists(dir / "new"));
  fs::create_symlink(dir / "nowhere", dir / "link");
  const std::string message =
      testing::error_message([&] { write_file_atomically(dir / "link" / "m.json", "{}"); });
  EXPECT_TRUE(testing::contains(message, "link: cannot create the folder")) << message;
  EXPECT_TRUE(fs::is_symlink(dir / "link"));
}

// Beside a file written into any folder (export's, eval's), only that file's temporaries that a
// killed writer left go (no process has a pid of 999999999), and not a running writer's.
TEST(AtomicFile, AFilesOwnStaleTemporariesAreRemoved) {
  TempDir dir;
  const std::string running = std::to_string(::getppid());
  const char* stale = "model.spz.tmp-999999999";
  const std::string kept[] = {"model.spz.tmp-" + running, "other.spz.tmp-999999999",
                              "model.spz.tmp-x"};
  std::ofstream(dir / stale) << "x";
  for (const std::string& name : kept) std::ofstream(dir / name) << "x";
  remove_stale_temporaries_of(dir / "model.spz");
  EXPECT_FALSE(fs::exists(dir / stale));
  for (const std::string& name : kept) EXPECT_TRUE(fs::exists(dir / name)) << name;
}

// Ctrl-C while a file is written, outside training: the process ends as the signal ends it, and
// neither the file, its temporary nor the folders made for it (export m new/x.ply) are left.
TEST(AtomicFile, ASignalMidWriteLeavesNoHalfWrittenFile) {
  TempDir dir;
  EXPECT_EQ(testing::ended_by([&] {
              end_on_signals(remove_temporaries_in_progress);
              write_atomically(dir / "new" / "deeper" / "model.ply", [](const fs::path& tmp) {
                std::ofstream(tmp) << "half";
                std::raise(SIGINT);
              });
            }),
            SIGINT);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
}  // namespace iesrgs
