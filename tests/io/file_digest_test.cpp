#include "io/file_digest.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::TempDir;
using testing::write_text;

TEST(FileDigest, FollowsTheBytesNotThePathOrTheTime) {
  TempDir dir;
  // Longer than one word and not a whole number of them, so both loops run.
  const std::string bytes = "a file of thirty-one bytes here";
  write_text(dir / "a.bin", bytes);
  write_text(dir / "sub/b.bin", bytes);
  std::filesystem::last_write_time(
      dir / "sub/b.bin", std::filesystem::file_time_type::clock::now() + std::chrono::hours(1));
  EXPECT_EQ(file_digest(dir / "a.bin"), file_digest(dir / "sub/b.bin"));
  EXPECT_EQ(file_digest(dir / "a.bin").size(), 16u);

  std::string edited = bytes;
  edited.back() = 'X';  // a tail byte
  write_text(dir / "tail.bin", edited);
  edited = bytes;
  edited[3] = 'X';  // a byte of the first word
  write_text(dir / "word.bin", edited);
  write_text(dir / "longer.bin", bytes + '\0');
  for (const char* other : {"tail.bin", "word.bin", "longer.bin"})
    EXPECT_NE(file_digest(dir / "a.bin"), file_digest(dir / other)) << other;
}

TEST(FileDigest, MissingFileHasAPlaceholder) {
  TempDir dir;
  EXPECT_EQ(file_digest(dir / "absent"), "-");
  EXPECT_EQ(file_digest({}), "-");
}

TEST(FileDigest, BytesInMemoryDigestLikeTheFileHoldingThem) {
  TempDir dir;
  const std::string bytes = "camera r_0 800x800 1111.1 1111.1 400 400";
  write_text(dir / "key.txt", bytes);
  EXPECT_EQ(bytes_digest(bytes), file_digest(dir / "key.txt"));
  EXPECT_NE(bytes_digest(bytes), bytes_digest(bytes.substr(1)));
}

TEST(FileDigest, DirectoryDigestFollowsItsFilesNamesAndContent) {
  TempDir dir;
  EXPECT_EQ(directory_digest(dir / "model"), "-");
  write_text(dir / "model/model.json", "{}");
  write_text(dir / "model/group1-shard1of1.bin", "weights");
  write_text(dir / "copy/group1-shard1of1.bin", "weights");
  write_text(dir / "copy/model.json", "{}");
  const std::string digest = directory_digest(dir / "model");
  EXPECT_EQ(directory_digest(dir / "copy"), digest);
  write_text(dir / "copy/group1-shard1of1.bin", "weightz");
  EXPECT_NE(directory_digest(dir / "copy"), digest);
  write_text(dir / "model/extra.bin", "");
  EXPECT_NE(directory_digest(dir / "model"), digest);
}

}  // namespace
}  // namespace iesrgs
