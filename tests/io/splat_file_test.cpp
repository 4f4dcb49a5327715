#include "io/splat_file.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/math.hpp"
#include "io/atomic_file.hpp"
#include "io/model_file.hpp"
#include "io/viewer_cloud.hpp"
#include "support/captured_log.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::contains;
using testing::error_message;
using testing::TempDir;

struct Record {
  std::array<float, 3> position, scale;
  std::array<uint8_t, 4> rgba, rotation;
};

std::vector<Record> decode(const std::string& bytes) {
  EXPECT_EQ(bytes.size() % kSplatRecordBytes, 0u);
  std::vector<Record> records(bytes.size() / kSplatRecordBytes);
  for (size_t i = 0; i < records.size(); ++i) {
    const char* at = bytes.data() + i * kSplatRecordBytes;
    std::memcpy(records[i].position.data(), at, 12);
    std::memcpy(records[i].scale.data(), at + 12, 12);
    std::memcpy(records[i].rgba.data(), at + 24, 4);
    std::memcpy(records[i].rotation.data(), at + 28, 4);
  }
  return records;
}

// Two Gaussians: a small faint one, then a large opaque one (which the file puts first).
SplatCloud two_gaussians() {
  SplatCloud cloud;
  cloud.positions = {1, 2, 3, -4, 5.5f, -6};
  cloud.sh_dc = {0, 1, -1, 1.7724539f, -1.7724539f, 0};  // 0.5 +- 0.5 at +-sqrt(pi)
  cloud.opacity = {-3, 2};
  cloud.log_scales = {-4, -4, -4, std::log(0.5f), std::log(0.25f), std::log(2.f)};
  cloud.rotations = {2, 0, 0, 0, 0.5f, 0.5f, -0.5f, 0.5f};  // scaled identity, a unit quaternion
  return cloud;
}

TEST(SplatFile, RecordsHoldActivatedValuesMostVisibleFirst) {
  TempDir dir;
  write_splat(dir / "scene.splat", two_gaussians());
  const std::vector<Record> records = decode(read_file(dir / "scene.splat"));
  ASSERT_EQ(records.size(), 2u);
  const Record& big = records[0];
  EXPECT_EQ(big.position, (std::array<float, 3>{-4, 5.5f, -6}));
  EXPECT_NEAR(big.scale[0], 0.5f, 1e-6);
  EXPECT_NEAR(big.scale[1], 0.25f, 1e-6);
  EXPECT_NEAR(big.scale[2], 2.f, 1e-6);
  EXPECT_EQ(big.rgba, (std::array<uint8_t, 4>{255, 0, 128,
                                              uint8_t(std::lround(255 / (1 + std::exp(-2.0))))}));
  EXPECT_EQ(big.rotation, (std::array<uint8_t, 4>{192, 192, 64, 192}));
  const Record& small = records[1];
  EXPECT_EQ(small.position, (std::array<float, 3>{1, 2, 3}));
  EXPECT_NEAR(small.scale[0], std::exp(-4.f), 1e-9);
  EXPECT_EQ(small.rgba[0], 128);                                            // f_dc 0 is mid grey
  EXPECT_EQ(small.rotation, (std::array<uint8_t, 4>{255, 128, 128, 128}));  // 256 clamped
}

TEST(SplatFile, MipFilterIsBakedIntoScaleAndOpacity) {
  TempDir dir;
  SplatCloud cloud = two_gaussians();
  cloud.filter_3d = {0, 0.5f};  // widens the big Gaussian's first axis from 0.5 to sqrt(0.5)
  write_splat(dir / "scene.splat", cloud);
  const Record big = decode(read_file(dir / "scene.splat"))[0];
  EXPECT_NEAR(big.scale[0], std::sqrt(0.5f), 1e-6);
  EXPECT_NEAR(big.scale[1], std::sqrt(0.25f * 0.25f + 0.25f), 1e-6);
  const double factor = std::sqrt(0.25 * 0.0625 * 4 / (0.5 * (0.0625 + 0.25) * (4 + 0.25)));
  EXPECT_EQ(big.rgba[3], uint8_t(std::lround(255 * factor / (1 + std::exp(-2.0)))));
}

TEST(SplatFile, UndrawableGaussiansAreLeftOutAndMalformedCloudsWriteNothing) {
  TempDir dir;
  SplatCloud cloud = two_gaussians();
  cloud.log_scales[4] = NAN;
  EXPECT_EQ(write_splat(dir / "nan.splat", cloud), 1u);
  EXPECT_EQ(decode(read_file(dir / "nan.splat")).size(), 1u);
  cloud = two_gaussians();
  cloud.log_scales[0] = 100;  // finite, but not once exponentiated into a float
  cloud.rotations[4] = cloud.rotations[5] = cloud.rotations[6] = cloud.rotations[7] = 0;
  const std::string none = error_message([&] { write_splat(dir / "a.splat", cloud); });
  EXPECT_TRUE(contains(none,
                       "a.splat: not written: no Gaussian of the model can be drawn (Gaussian 0 "
                       "has a scale that is no finite"))
      << none;
  cloud = two_gaussians();
  cloud.positions[0] = 1e30f;  // far, but a valid position
  write_splat(dir / "far.splat", cloud);
  EXPECT_EQ(decode(read_file(dir / "far.splat"))[1].position[0], 1e30f);
  std::filesystem::remove(dir / "far.splat");
  cloud = two_gaussians();
  cloud.opacity.pop_back();
  const std::string short_array = error_message([&] { write_splat(dir / "b.splat", cloud); });
  EXPECT_TRUE(contains(short_array, "b.splat: the array of 'opacity' holds 1 values"))
      << short_array;
  EXPECT_FALSE(std::filesystem::exists(dir / "a.splat"));
  EXPECT_FALSE(std::filesystem::exists(dir / "b.splat"));
}

// One record's 32 bytes from its fields.
std::string encode(const Record& r) {
  std::string bytes(kSplatRecordBytes, '\0');
  std::memcpy(&bytes[0], r.position.data(), 12);
  std::memcpy(&bytes[12], r.scale.data(), 12);
  std::memcpy(&bytes[24], r.rgba.data(), 4);
  std::memcpy(&bytes[28], r.rotation.data(), 4);
  return bytes;
}

TEST(SplatFile, ReadsBackWhatItWroteWithinTheFormatsSteps) {
  TempDir dir;
  const SplatCloud written = two_gaussians();
  write_splat(dir / "scene.SPLAT", written);
  const SplatCloud read = read_model(dir / "scene.SPLAT");  // by its extension, in any case
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read.sh_degree, 0);
  EXPECT_TRUE(read.sh_rest.empty());
  EXPECT_FALSE(read.antialiased);  // drawn as the viewers draw it
  EXPECT_FALSE(read.has_filter_3d());
  for (size_t i = 0; i < 2; ++i) {
    const size_t from = 1 - i;  // the file holds the big opaque Gaussian first
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(read.positions[3 * i + k], written.positions[3 * from + k]);
      EXPECT_NEAR(read.log_scales[3 * i + k], written.log_scales[3 * from + k], 1e-6);
      EXPECT_NEAR(0.5 + kShC0 * read.sh_dc[3 * i + k], 0.5 + kShC0 * written.sh_dc[3 * from + k],
                  0.5 / 255 + 1e-6);
    }
    EXPECT_NEAR(sigmoid(read.opacity[i]), sigmoid(written.opacity[from]), 0.5 / 255 + 1e-6);
    const double norm = quaternion_norm(&written.rotations[4 * from]);
    for (int k = 0; k < 4; ++k)
      EXPECT_NEAR(read.rotations[4 * i + k], written.rotations[4 * from + k] / norm, 1.0 / 128);
  }
}

TEST(SplatFile, DegenerateRecordsAreMadeUsable) {
  Record r{{1, 2, 3}, {0, 1, 1}, {0, 0, 0, 255}, {128, 128, 128, 128}};
  const SplatCloud cloud = parse_splat(encode(r), "z.splat");
  EXPECT_EQ(cloud.log_scales[0], std::log(std::numeric_limits<float>::min()));  // not -inf
  EXPECT_EQ(cloud.rotations, (std::vector<float>{1, 0, 0, 0}));                 // identity
  EXPECT_TRUE(std::isfinite(cloud.opacity[0]));  // byte 255 is not a logit of +inf
  EXPECT_GT(sigmoid(cloud.opacity[0]), 0.99);
}

// As a .ply's: a record that is not finite is left out, with a warning, and the others load.
TEST(SplatFile, RecordsNotFiniteAreLeftOutWithAWarning) {
  const Record good{{1, 2, 3}, {1, 1, 1}, {9, 9, 9, 9}, {255, 128, 128, 128}};
  Record far = good, wide = good;
  far.position[2] = INFINITY;
  wide.scale[0] = NAN;
  testing::CapturedLog log;
  const SplatCloud cloud = parse_splat(encode(far) + encode(good) + encode(wide), "p.splat");
  EXPECT_EQ(cloud.positions, (std::vector<float>{1, 2, 3}));
  EXPECT_EQ(cloud.rotations.size(), 4u);
  EXPECT_EQ(log.count("p.splat: 2 of 3 Gaussians are left out for holding a value that is not "
                      "finite (first, record 0: position inf is not finite)"),
            1u)
      << log.text();
}

TEST(SplatFile, MalformedFilesAreErrorsNamingTheFile) {
  const Record good{{1, 2, 3}, {1, 1, 1}, {9, 9, 9, 9}, {255, 128, 128, 128}};
  EXPECT_TRUE(contains(error_message([] { parse_splat("", "e.splat"); }),
                       "e.splat: is empty: no Gaussians"));
  EXPECT_TRUE(contains(error_message([&] { parse_splat(encode(good) + "x", "t.splat"); }),
                       "t.splat: is 33 bytes, not a whole number of 32-byte .splat records"));
  Record nan = good;
  nan.position[1] = NAN;
  EXPECT_TRUE(
      contains(error_message([&] { parse_splat(encode(nan), "n.splat"); }),
               "n.splat: every Gaussian is left out: record 0: position nan is not finite"));
  Record negative = good;
  negative.scale[2] = -1;
  EXPECT_TRUE(contains(error_message([&] { parse_splat(encode(negative), "s.splat"); }),
                       "s.splat: record 0: scale -1 is negative"));
  EXPECT_TRUE(contains(error_message([&] { read_splat("/nonexistent/m.splat"); }), "m.splat"));
}

}  // namespace
}  // namespace iesrgs
