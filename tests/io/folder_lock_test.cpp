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

TEST(FolderLock, AFileInTheWayIsNamed) {
  TempDir dir;
  const auto file = dir / "taken";
  { std::ofstream(file) << "x"; }
  const std::string message = error_message([&] { FolderLock lock(file); });
  EXPECT_TRUE(contains(message, file.string() + ": cannot")) << message;
}

}  // namespace
}  // namespace iesrgs
