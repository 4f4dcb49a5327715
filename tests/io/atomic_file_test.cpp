#include "io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>

#include "core/interrupt.hpp"
#include "support/ended_by.hpp"
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
