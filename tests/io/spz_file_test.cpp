#include "io/spz_file.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "core/math.hpp"
#include "io/atomic_file.hpp"
#include "io/viewer_cloud.hpp"
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
  SplatCloud classic = one_gaussian();
  classic.antialiased = false;
  const std::string bytes = written(dir, classic);
  EXPECT_EQ(bytes.substr(0, 4), "NGSP");
  EXPECT_EQ(u32_at(bytes, 4), 3u);
  EXPECT_EQ(u32_at(bytes, 8), 1u);
  EXPECT_EQ(bytes[12], 0);   // SH degree
  EXPECT_EQ(bytes[13], 12);  // fractional bits
  EXPECT_EQ(bytes[14], 0);   // drawn with 3DGS's dilation: not antialiased
  EXPECT_EQ(position_at(bytes, 0), 2048);
  EXPECT_EQ(position_at(bytes, 1), -1024);
  EXPECT_EQ(bytes.size(), kHeaderBytes + 9 + 1 + 3 + 3 + 4);
}

TEST(SpzFile, MipFilterIsBakedAndFlagsTheModelAntialiased) {
  TempDir dir;
  SplatCloud filtered = one_gaussian();
  filtered.filter_3d = {0.1f};
  const std::string with_filter = written(dir, filtered);
  EXPECT_EQ(with_filter[14], 1);
  EXPECT_EQ(written(dir, bake_filter_3d(filtered)), with_filter);  // baking keeps the flag
  EXPECT_NE(with_filter, written(dir, one_gaussian()));  // the filter did change scales and opacity
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
  EXPECT_TRUE(contains(nan,
                       "a.spz: not written: no Gaussian of the model can be drawn (Gaussian 0 has "
                       "a non-finite colour"))
      << nan;
  cloud = one_gaussian();
  cloud.positions[0] = 1e7f;
  const std::string far = error_message([&] { write_spz(dir / "a.spz", cloud); });
  EXPECT_TRUE(contains(far, "a.spz: a Gaussian lies 1e+07 units from the origin")) << far;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.spz"));
}

void expect_values_near(const std::vector<float>& got, const std::vector<float>& want,
                        double tolerance, const char* field) {
  ASSERT_EQ(got.size(), want.size()) << field;
  for (size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], tolerance) << field << i;
}

void expect_clouds_near(const SplatCloud& got, const SplatCloud& want, double tolerance) {
  EXPECT_EQ(got.sh_degree, want.sh_degree);
  EXPECT_FALSE(got.has_filter_3d());
  expect_values_near(got.positions, want.positions, tolerance, "position");
  expect_values_near(got.sh_dc, want.sh_dc, tolerance, "f_dc");
  expect_values_near(got.sh_rest, want.sh_rest, tolerance, "f_rest");
  expect_values_near(got.opacity, want.opacity, tolerance, "opacity");
  expect_values_near(got.log_scales, want.log_scales, tolerance, "log scale");
  expect_values_near(got.rotations, want.rotations, tolerance, "rotation");
}

// reference_v*_decoded.ply: what the reference decoder (its spz_to_ply) makes of each file that
// the reference encoder wrote from cloud.ply: version 2 (gzip, rotations as x y z), 3 (gzip,
// smallest three), 4 (zstd stream per attribute), and 4 at SH degree 0, where the SH stream is
// left out. Versions 3 and 4 quantize alike.
TEST(SpzRead, DecodesEveryVersionAsTheReferenceDecoder) {
  const std::pair<const char*, const char*> files[] = {
      {"reference_v2.spz", "reference_v2_decoded.ply"},
      {"reference_v3.spz", "reference_v4_decoded.ply"},
      {"reference_v4.spz", "reference_v4_decoded.ply"},
      {"reference_v4_degree0.spz", "reference_v4_degree0_decoded.ply"}};
  for (const auto& [spz, decoded] : files) {
    SCOPED_TRACE(spz);
    expect_clouds_near(read_spz(kData / spz), read_ply(kData / decoded), 1e-6);
  }
}

TEST(SpzRead, TheAntialiasedFlagSaysHowToDrawTheCloud) {
  TempDir dir;
  EXPECT_FALSE(read_spz(kData / "reference_v4.spz").antialiased);  // 3DGS's own layout
  for (bool antialiased : {false, true}) {
    SplatCloud cloud = one_gaussian();
    cloud.antialiased = antialiased;
    write_spz(dir / "a.spz", cloud);
    EXPECT_EQ(read_spz(dir / "a.spz").antialiased, antialiased);
  }
}

TEST(SpzRead, WrittenCloudsComeBackWithinTheirQuantization) {
  TempDir dir;
  SplatCloud cloud = one_gaussian();
  cloud.sh_degree = 1;
  cloud.sh_rest = {0.1f, -0.2f, 0.3f, 0.4f, -0.5f, 0.6f, -0.7f, 0.8f, -0.9f};
  cloud.rotations = {0.3f, -0.5f, 0.2f, 0.7f};
  write_spz(dir / "a.spz", cloud);
  const SplatCloud back = read_spz(dir / "a.spz");
  expect_values_near(back.positions, cloud.positions, 0.5 / 4096, "position");
  expect_values_near(back.log_scales, cloud.log_scales, 0.5 / 16, "log scale");
  expect_values_near(back.sh_dc, cloud.sh_dc, 0.51 / 255 / 0.15,
                     "f_dc");                                            // 0.5 sits at a half step
  expect_values_near(back.sh_rest, cloud.sh_rest, 4.0 / 128, "f_rest");  // 5-bit buckets
  EXPECT_NEAR(sigmoid(back.opacity[0]), sigmoid(cloud.opacity[0]), 0.51 / 255);
  // The same rotation, up to sign, to the 9 bits of each small component.
  const double norm = quaternion_norm(cloud.rotations.data());
  double dot = 0;
  for (int k = 0; k < 4; ++k) dot += back.rotations[k] * cloud.rotations[k] / norm;
  EXPECT_NEAR(std::fabs(dot), 1.0, 1e-5);
}

TEST(SpzRead, SaturatedOpacitiesStayFinite) {
  TempDir dir;
  SplatCloud cloud = one_gaussian();
  for (float logit : {-30.f, 30.f}) {
    cloud.opacity = {logit};
    write_spz(dir / "a.spz", cloud);
    const float back = read_spz(dir / "a.spz").opacity[0];
    ASSERT_TRUE(std::isfinite(back)) << logit;
    EXPECT_NEAR(sigmoid(back), logit < 0 ? 0.5 / 255 : 254.5 / 255, 1e-6);
  }
}

// A one-Gaussian gzip .spz of the given version whose rotation is `rotation` (3 bytes for
// version 2, 4 after) and whose higher SH bands are `sh`, of `degree`; everything else zero.
void write_legacy_spz(const std::filesystem::path& path, uint8_t version,
                      const std::string& rotation, uint8_t degree = 0, const std::string& sh = "") {
  std::string bytes("NGSP", 4);
  bytes += std::string{char(version), 0, 0, 0, 1, 0, 0, 0, char(degree), 12, 0, 0};  // count 1
  bytes += std::string(9 + 1 + 3 + 3, '\0') + rotation + sh;
  gzFile file = gzopen(path.c_str(), "wb");
  ASSERT_NE(file, nullptr);
  ASSERT_EQ(gzwrite(file, bytes.data(), unsigned(bytes.size())), int(bytes.size()));
  ASSERT_EQ(gzclose(file), Z_OK);
}

// No encoder writes three stored components longer than 1, but a file can hold them.
TEST(SpzRead, OverlongRotationsComeBackNormalized) {
  TempDir dir;
  const std::pair<uint8_t, std::string> files[] = {
      {2, std::string(3, '\xff')},                        // x = y = z = 1
      {3, std::string{'\xff', '\xff', '\xff', '\xdf'}}};  // all three at 1/sqrt(2), w dropped
  for (const auto& [version, rotation] : files) {
    SCOPED_TRACE(int(version));
    write_legacy_spz(dir / "a.spz", version, rotation);
    const SplatCloud cloud = read_spz(dir / "a.spz");
    ASSERT_EQ(cloud.rotations.size(), 4u);
    EXPECT_NEAR(quaternion_norm(cloud.rotations.data()), 1.0, 1e-6);
    EXPECT_EQ(cloud.rotations[0], 0.0f);  // the completed component: nothing left for it
    EXPECT_NEAR(cloud.rotations[1], 1 / std::sqrt(3.0), 1e-6);
  }
}

// Niantic's library writes SH up to degree 4; the renderer draws up to 3, so the fourth band goes.
TEST(SpzRead, DegreeFourKeepsTheFirstThreeBands) {
  TempDir dir;
  std::string sh;
  for (int k = 0; k < 3 * 24; ++k) sh += char(k);  // 24 coefficients per channel
  write_legacy_spz(dir / "a.spz", 3, std::string(4, '\0'), 4, sh);
  const SplatCloud cloud = read_spz(dir / "a.spz");
  EXPECT_EQ(cloud.sh_degree, 3);
  ASSERT_EQ(cloud.sh_rest.size(), 45u);
  for (int k = 0; k < 45; ++k) EXPECT_FLOAT_EQ(cloud.sh_rest[k], (k - 128) / 128.0f) << k;
  sh += std::string(3 * 11, '\0');  // degree 5's extra coefficients: no format allows it
  write_legacy_spz(dir / "b.spz", 3, std::string(4, '\0'), 5, sh);
  const std::string message = error_message([&] { read_spz(dir / "b.spz"); });
  EXPECT_TRUE(contains(message, "b.spz: SH degree 5 is above 4")) << message;
}

TEST(SpzRead, MalformedFilesNameTheFileAndTheProblem) {
  TempDir dir;
  const std::string v3 = read_file(kData / "reference_v3.spz");
  const std::string v4 = read_file(kData / "reference_v4.spz");
  const auto problem = [&](const std::string& bytes) {
    write_file_atomically(dir / "bad.spz", bytes);
    return error_message([&] { read_spz(dir / "bad.spz"); });
  };
  std::string future = v4, streams = v4;
  future[4] = 9;    // version
  streams[15] = 5;  // stream count
  const std::pair<std::string, const char*> cases[] = {
      {"ply\nformat ascii 1.0\n", "bad.spz: not an .spz file"},
      {v3.substr(0, v3.size() / 2), "bad.spz: corrupt or truncated gzip stream"},
      {v4.substr(0, 40), "bad.spz: truncated data"},
      {v4.substr(0, v4.size() - 10), "bad.spz: truncated data"},
      {future, "bad.spz: unsupported .spz version 9"},
      {streams, "bad.spz: 5 attribute streams where 7 Gaussians of SH degree 3 need 6"}};
  for (const auto& [bytes, expected] : cases) {
    const std::string message = problem(bytes);
    EXPECT_TRUE(contains(message, expected)) << message;
  }
  const std::string missing = error_message([&] { read_spz(dir / "none.spz"); });
  EXPECT_TRUE(contains(missing, "none.spz")) << missing;
}

}  // namespace
}  // namespace iesrgs
