#include "io/folder_lock.hpp"

#include <gtest/gtest.h>
#include <csignal>
#include <fstream>
#include <optional>

#include "core/interrupt.hpp"
#include "io/atomic_file.hpp"
#include "support/child_process.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::contains;
using testing::error_message;
using testing::TempDir;

TEST(FolderLock, OneHolderAtATime) {
  TempDir dir;
  const auto folder = dir / "run" / "nested";
  std::optional<FolderLock> first(folder);
  EXPECT_TRUE(std::filesystem::is_directory(folder));
  const std::string message = error_message([&] { FolderLock second(folder); });
  EXPECT_TRUE(contains(message, folder.string() + ": in use by another process")) << message;
  first.reset();
  FolderLock again(folder);
  EXPECT_TRUE(std::filesystem::is_empty(folder));  // no lock file among the outputs
}

TEST(FolderLock, AFolderInsideAHeldOneIsRefused) {
  TempDir dir;
  std::optional<FolderLock> run(dir / "run");
  const auto stage = dir / "run" / "internal";
  const std::string message = error_message([&] { FolderLock train(stage); });
  EXPECT_TRUE(contains(message, stage.string() + ": inside " + (dir / "run").string() +
                                    ", which another process is writing"))
      << message;
  EXPECT_FALSE(std::filesystem::exists(stage));
  run.reset();
  std::optional<FolderLock> train(stage);
  FolderLock beside(dir / "other");  // held folders lock only what is inside them
  // Nor is a run taken over a stage folder that a training holds.
  const std::string above = error_message([&] { FolderLock rerun(dir / "run"); });
  EXPECT_TRUE(contains(above, (dir / "run").string() + ": above " + stage.string() +
                                  ", which another process is writing"))
      << above;
  train.reset();
  FolderLock rerun(dir / "run");
}

TEST(FolderLock, FoldersItCreatedAndLeftEmptyAreRemoved) {
  TempDir dir;
  { FolderLock unused(dir / "new" / "run"); }
  EXPECT_FALSE(std::filesystem::exists(dir / "new"));
  { FolderLock unused(dir / "slash" / "run/"); }  // as -o slash/run/ names it
  EXPECT_FALSE(std::filesystem::exists(dir / "slash"));
  {
    FolderLock written(dir / "kept" / "run");
    std::ofstream(dir / "kept" / "run" / "out.txt") << "x";
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "kept" / "run" / "out.txt"));
  std::filesystem::create_directory(dir / "given");
  { FolderLock unused(dir / "given"); }
  EXPECT_TRUE(std::filesystem::is_directory(dir / "given"));  // the user's own folder stays
}

// Ctrl-C before the first output: the folders the lock created go with the temporary, as they do
// when it is released; with an output in them, they stay.
TEST(FolderLock, ASignalRemovesTheFoldersItCreatedWhileEmpty) {
  TempDir dir;
  for (bool with_output : {false, true}) {
    EXPECT_EQ(testing::ended_by([&] {
                end_on_signals(remove_temporaries_in_progress);
                const FolderLock lock(dir / "new" / "out");
                if (with_output) write_file_atomically(dir / "new" / "out" / "done.json", "{}");
                write_atomically(dir / "new" / "out" / "model.ply",
                                 [](const std::filesystem::path& tmp) {
                                   std::ofstream(tmp) << "half";
                                   std::raise(SIGINT);
                                 });
              }),
              SIGINT);
    EXPECT_EQ(std::filesystem::exists(dir / "new" / "out" / "done.json"), with_output);
    EXPECT_EQ(std::filesystem::exists(dir / "new"), with_output);
    EXPECT_FALSE(std::filesystem::exists(dir / "new" / "out" / "model.ply"));
  }
}

// A writer killed mid-write leaves "<name>.tmp-<pid>". Only our outputs' temporaries go, in the
// folder and four levels of subfolders (a run's rows/<row>/test/rgb/), and only when their writer
// is gone (no process has a pid of 999999999).
TEST(FolderLock, TakingItRemovesWhatKilledWritersLeft) {
  TempDir dir;
  std::filesystem::create_directories(dir / "run" / "rows/ie-srgs/test/rgb/deeper");
  const char* files[] = {"checkpoint.pt.tmp-999999999",
                         "rows/ie-srgs/test/rgb/r_0.png.tmp-999999999", "notes.tmp-999999999",
                         "draft.png.tmp-x", "rows/ie-srgs/test/rgb/deeper/r_1.png.tmp-999999999"};
  for (const char* name : files) std::ofstream(dir / "run" / name) << "x";
  FolderLock lock(dir / "run");
  for (const char* gone : {files[0], files[1]})
    EXPECT_FALSE(std::filesystem::exists(dir / "run" / gone)) << gone;
  for (const char* kept : {files[2], files[3], files[4]})
    EXPECT_TRUE(std::filesystem::exists(dir / "run" / kept)) << kept;
}

TEST(FolderLock, AFileInTheWayIsNamed) {
  TempDir dir;
  const auto file = dir / "taken";
  { std::ofstream(file) << "x"; }
  const std::string message = error_message([&] { FolderLock lock(file); });
  EXPECT_TRUE(contains(message, file.string() + ": cannot")) << message;
}

}  // namespace
}  // namespace iesrgs
