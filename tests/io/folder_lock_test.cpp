#include "io/folder_lock.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <optional>

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
  EXPECT_TRUE(contains(message, folder.string() + ": in use by another iesrgs process")) << message;
  first.reset();
  FolderLock again(folder);
  EXPECT_TRUE(std::filesystem::is_empty(folder));  // no lock file among the outputs
}

TEST(FolderLock, FoldersItCreatedAndLeftEmptyAreRemoved) {
  TempDir dir;
  { FolderLock unused(dir / "new" / "run"); }
  EXPECT_FALSE(std::filesystem::exists(dir / "new"));
  {
    FolderLock written(dir / "kept" / "run");
    std::ofstream(dir / "kept" / "run" / "out.txt") << "x";
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "kept" / "run" / "out.txt"));
  std::filesystem::create_directory(dir / "given");
  { FolderLock unused(dir / "given"); }
  EXPECT_TRUE(std::filesystem::is_directory(dir / "given"));  // the user's own folder stays
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
