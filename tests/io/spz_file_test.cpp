#include "io/spz_file.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "io/atomic_file.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::contains;
using testing::error_message;
using testing::TempDir;

const std::filesystem::path kData = std::filesystem::path(IESRGS_TEST_DATA) / "spz";
constexpr size_t kHeaderBytes = 16;

std::string gunzip(const std::string& bytes) {
  z_stream stream{};
  EXPECT_EQ(inflateInit2(&stream, 16 + MAX_WBITS), Z_OK);
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  stream.avail_in = uInt(bytes.size());
  std::string out;
  char buffer[4096];
  int status = Z_OK;
  while (status == Z_OK) {
    stream.next_out = reinterpret_cast<Bytef*>(buffer);
    stream.avail_out = sizeof buffer;
    status = inflate(&stream, Z_NO_FLUSH);
    out.append(buffer, sizeof buffer - stream.avail_out);
  }
  inflateEnd(&stream);
  EXPECT_EQ(status, Z_STREAM_END) << "not a complete gzip stream";
  return out;
}

std::string written(const TempDir& dir, const SplatCloud& cloud) {
  write_spz(dir / "scene.spz", cloud);
  return gunzip(read_file(dir / "scene.spz"));
}

uint32_t u32_at(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  for (int b = 3; b >= 0; --b) v = v << 8 | uint8_t(bytes[at + b]);
  return v;
}

int32_t position_at(const std::string& bytes, size_t index) {
  const size_t at = kHeaderBytes + 3 * index;
  const uint32_t v =
      uint8_t(bytes[at]) | uint8_t(bytes[at + 1]) << 8 | uint8_t(bytes[at + 2]) << 16;
  return int32_t(v << 8) >> 8;  // sign-extend the 24 bits
}

SplatCloud one_gaussian() {
  SplatCloud cloud;
  cloud.positions = {0.5f, -0.25f, 1};
  cloud.sh_dc = {0, 1, -1};
  cloud.opacity = {0};
  cloud.log_scales = {-3, -2, -1};
  cloud.rotations = {1, 0, 0, 0};
  return cloud;
}

// cloud.ply (seven Gaussians with degree-3 SH, rotations of every sign, values beyond each
// field's range) and reference_v3.spz, what Niantic's own library encodes from it (README.md).
TEST(SpzFile, MatchesTheReferenceEncoderByteForByte) {
  TempDir dir;
  const std::string ours = written(dir, read_ply(kData / "cloud.ply"));
  const std::string reference = gunzip(read_file(kData / "reference_v3.spz"));
  ASSERT_EQ(ours.size(), reference.size());
  for (size_t i = 0; i < ours.size(); ++i)
    ASSERT_EQ(uint8_t(ours[i]), uint8_t(reference[i])) << "byte " << i;
}

TEST(SpzFile, HeaderNamesFormatCountAndDegree) {
  TempDir dir;
  const std::string bytes = written(dir, one_gaussian());
  EXPECT_EQ(bytes.substr(0, 4), "NGSP");
  EXPECT_EQ(u32_at(bytes, 4), 3u);
  EXPECT_EQ(u32_at(bytes, 8), 1u);
  EXPECT_EQ(bytes[12], 0);   // SH degree
  EXPECT_EQ(bytes[13], 12);  // fractional bits
  EXPECT_EQ(bytes[14], 0);   // no 3D filter: not antialiased
  EXPECT_EQ(position_at(bytes, 0), 2048);
  EXPECT_EQ(position_at(bytes, 1), -1024);
  EXPECT_EQ(bytes.size(), kHeaderBytes + 9 + 1 + 3 + 3 + 4);
}

TEST(SpzFile, MipFilterIsBakedAndFlagsTheModelAntialiased) {
  TempDir dir;
  SplatCloud filtered = one_gaussian();
  filtered.filter_3d = {0.1f};
  const std::string with_filter = written(dir, filtered);
  const std::string baked = written(dir, bake_filter_3d(filtered));
  EXPECT_EQ(with_filter[14], 1);
  EXPECT_EQ(baked[14], 0);
  EXPECT_EQ(with_filter.substr(15), baked.substr(15));
  EXPECT_NE(baked, written(dir, one_gaussian()));  // the filter did change scales and opacity
}

TEST(SpzFile, FarGaussiansKeepTheirPlaceWithFewerFractionalBits) {
  TempDir dir;
  SplatCloud cloud = one_gaussian();
  cloud.positions[2] = -3000;  // 24 bits with 12 fractional bits reach 2048
  const std::string bytes = written(dir, cloud);
  EXPECT_EQ(bytes[13], 11);
  EXPECT_EQ(position_at(bytes, 2), -3000 * 2048);
  EXPECT_EQ(position_at(bytes, 0), 1024);
}

TEST(SpzFile, UnstorableCloudsAreErrorsAndWriteNothing) {
  TempDir dir;
  SplatCloud cloud = one_gaussian();
  cloud.sh_degree = 1;
  cloud.sh_rest = {0, 0, 0, 0, NAN, 0, 0, 0, 0};
  const std::string nan = error_message([&] { write_spz(dir / "a.spz", cloud); });
  EXPECT_TRUE(contains(nan, "a.spz: Gaussian 0 has a non-finite")) << nan;
  cloud = one_gaussian();
  cloud.positions[0] = 1e7f;
  const std::string far = error_message([&] { write_spz(dir / "a.spz", cloud); });
  EXPECT_TRUE(contains(far, "a.spz: a Gaussian lies 1e+07 units from the origin")) << far;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.spz"));
}

}  // namespace
}  // namespace iesrgs
