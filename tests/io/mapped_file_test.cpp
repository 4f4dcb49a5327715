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

TEST(MappedFile, ReadsThroughAcrossDroppedPagesAndStopsAtTheEnd) {
  TempDir dir;
  std::string bytes(3 * 4096 + 100, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i * 7 % 251);
  write_text(dir / "a.bin", bytes);
  const MappedFile file(dir / "a.bin");
  file.drop_pages(0, bytes.size());  // read again from the file when touched
  std::string copy(bytes.size(), '\0');
  size_t offset = 0;
  // Chunks of more than a page, so that each drops the pages it read whole.
  for (size_t chunk : {5000, 3000, 5000})
    offset += file.read_through(offset, copy.data() + offset, chunk);
  EXPECT_EQ(offset, bytes.size());
  EXPECT_EQ(copy, bytes);
  char tail[8];
  EXPECT_EQ(file.read_through(bytes.size() - 3, tail, sizeof tail), 3u);
  EXPECT_EQ(std::string(tail, 3), bytes.substr(bytes.size() - 3));
  EXPECT_EQ(file.read_through(bytes.size() + 5, tail, sizeof tail), 0u);
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
