#include "io/mapped_file.hpp"

#include <gtest/gtest.h>

#include <string>

#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::contains;
using testing::error_message;
using testing::TempDir;
using testing::write_text;

TEST(MappedFile, ViewsTheFileBytes) {
  TempDir dir;
  const std::string bytes("binary\0bytes\xff", 13);
  write_text(dir / "a.bin", bytes);
  const MappedFile file(dir / "a.bin");
  EXPECT_EQ(file.bytes(), bytes);
}

TEST(MappedFile, EmptyFileIsAnEmptyView) {
  TempDir dir;
  write_text(dir / "empty", "");
  EXPECT_TRUE(MappedFile(dir / "empty").bytes().empty());
}

TEST(MappedFile, MissingFileOrFolderNamesThePath) {
  TempDir dir;
  const std::string missing = error_message([&] { MappedFile(dir / "missing.pt"); });
  EXPECT_TRUE(contains(missing, "missing.pt: cannot open for reading")) << missing;
  const std::string folder = error_message([&] { MappedFile file(dir.path()); });
  EXPECT_TRUE(contains(folder, "not a regular file")) << folder;
}

}  // namespace
}  // namespace iesrgs
