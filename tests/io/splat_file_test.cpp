#include "io/splat_file.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <string>

#include "io/atomic_file.hpp"
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

TEST(SplatFile, NonFiniteOrMalformedCloudsAreErrorsAndWriteNothing) {
  TempDir dir;
  SplatCloud cloud = two_gaussians();
  cloud.log_scales[4] = NAN;
  const std::string bad = error_message([&] { write_splat(dir / "a.splat", cloud); });
  EXPECT_TRUE(contains(bad, "a.splat: Gaussian 1 has a non-finite")) << bad;
  cloud = two_gaussians();
  cloud.log_scales[0] = 100;  // finite, but not once exponentiated into a float
  const std::string huge = error_message([&] { write_splat(dir / "a.splat", cloud); });
  EXPECT_TRUE(contains(huge, "a.splat: Gaussian 0 has a non-finite")) << huge;
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

}  // namespace
}  // namespace iesrgs
