#include <gtest/gtest.h>

#include "io/atomic_file.hpp"
#include "io/npy.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::error_message;
using testing::TempDir;
using testing::write_text;

TEST(Npy, RoundTrip) {
  TempDir dir;
  const std::vector<float> values{0.f, 1.5f, -2.f, 3.25f, 1e-7f, 42.f};
  write_npy(dir / "a.npy", values, {2, 3});
  const NpyArray back = read_npy(dir / "a.npy");
  EXPECT_EQ(back.shape, (std::vector<size_t>{2, 3}));
  EXPECT_EQ(back.data, values);
}

// A zero dimension: no data at all (memcpy may not be given the empty array's null pointer).
TEST(Npy, AnArrayWithNoElementsRoundTrips) {
  testing::TempDir dir;
  write_npy(dir / "empty.npy", {}, {0, 3});
  const NpyArray array = read_npy(dir / "empty.npy");
  EXPECT_EQ(array.shape, (std::vector<size_t>{0, 3}));
  EXPECT_TRUE(array.data.empty());
}

TEST(Npy, HeaderIsNumpyVersionOneAlignedTo64Bytes) {
  TempDir dir;
  write_npy(dir / "v.npy", {1.f, 2.f, 3.f}, {3});
  const std::string bytes = read_file(dir / "v.npy");
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  const size_t header_len = uint8_t(bytes[8]) | (uint8_t(bytes[9]) << 8);
  EXPECT_EQ((10 + header_len) % 64, 0u);
  EXPECT_NE(bytes.find("'shape': (3,)"), std::string::npos);
  EXPECT_EQ(bytes.size(), 10 + header_len + 3 * sizeof(float));
}

TEST(Npy, RejectsWhatItCannotRead) {
  TempDir dir;
  write_npy(dir / "ok.npy", {1.f, 2.f}, {2});
  const std::string ok = read_file(dir / "ok.npy");
  write_text(dir / "magic.npy", "NOTNUMPY" + ok.substr(8));
  write_text(dir / "short.npy", ok.substr(0, ok.size() - 2));
  std::string doubles = ok;
  doubles.replace(doubles.find("<f4"), 3, "<f8");
  write_text(dir / "f8.npy", doubles);
  EXPECT_NE(error_message([&] { read_npy(dir / "magic.npy"); }).find("magic.npy: not a .npy"),
            std::string::npos);
  EXPECT_NE(error_message([&] { read_npy(dir / "short.npy"); }).find("short.npy: data size"),
            std::string::npos);
  EXPECT_NE(error_message([&] { read_npy(dir / "f8.npy"); }).find("f8.npy: only little-endian"),
            std::string::npos);
  EXPECT_NE(error_message([&] { read_npy(dir / "missing.npy"); }).find("file not found"),
            std::string::npos);
}

TEST(AtomicFile, FailedWriteLeavesNoFile) {
  TempDir dir;
  EXPECT_THROW(
      write_atomically(dir / "out.bin", [](const std::filesystem::path&) { throw Error("boom"); }),
      Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  write_file_atomically(dir / "sub" / "out.bin", "payload");
  EXPECT_EQ(read_file(dir / "sub" / "out.bin"), "payload");
}

}  // namespace
}  // namespace iesrgs
