#include "pipeline/diagnostics.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <array>
#include <filesystem>
#include <string>

#include "io/atomic_file.hpp"
#include "io/image.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::TempDir;

// A gray (3, 1, 4) image whose pixels x = 0..3 hold `values`.
torch::Tensor row_image(std::array<float, 4> values) {
  return torch::tensor({values[0], values[1], values[2], values[3]})
      .view({1, 1, 4})
      .expand({3, 1, 4});
}

std::array<uint8_t, 3> rgb_at(const Image8& image, int x) {
  return {image.at(x, 0, 0), image.at(x, 0, 1), image.at(x, 0, 2)};
}

// Truth 0.5 everywhere. Pixel 0: both references exact (no mask). Pixel 1: the external image far
// off, the internal one exact (M picks the internal image, rightly). Pixel 2: the internal image
// dark and wrong (M picks it, wrongly). Pixel 3: the external image a little off, the internal
// one exact, too little for M.
TEST(Diagnostics, MaskCheckColorsWhereTheMaskIsRightWrongOrMissing) {
  TempDir dir;
  const torch::Tensor truth = row_image({0.5f, 0.5f, 0.5f, 0.5f});
  const DiagnosticView view{"v",
                            row_image({0.5f, 0.9f, 0.5f, 0.45f}),
                            row_image({0.5f, 0.5f, 0.1f, 0.5f}),
                            truth,
                            torch::ones({1, 4}),
                            truth};
  write_diagnostics(dir.path(), {view}, 0.6);
  const Image8 check = read_image8(dir / "v" / "mask_check.png");
  ASSERT_EQ(check.width, 4);
  using Rgb = std::array<uint8_t, 3>;
  EXPECT_EQ(rgb_at(check, 0), (Rgb{0, 0, 0}));
  EXPECT_EQ(rgb_at(check, 1), (Rgb{0, 255, 0}));
  EXPECT_EQ(rgb_at(check, 2), (Rgb{255, 0, 0}));
  EXPECT_EQ(rgb_at(check, 3), (Rgb{89, 89, 89}));
  const Image8 mask = read_image8(dir / "v" / "mask.png");
  EXPECT_EQ(rgb_at(mask, 1), (Rgb{255, 255, 255}));
  EXPECT_EQ(rgb_at(mask, 3), (Rgb{0, 0, 0}));
  EXPECT_EQ(read_image8(dir / "contact_sheet.png").width, 8 * 4);
}

// A user's own LR capture has no truth: no check, and the sheet keeps the column black.
TEST(Diagnostics, NoTruthNoMaskCheck) {
  TempDir dir;
  const torch::Tensor gray = row_image({0.5f, 0.5f, 0.5f, 0.5f});
  write_diagnostics(dir.path(), {{"v", gray, gray, gray, torch::ones({1, 4}), {}}}, 0.6);
  EXPECT_TRUE(std::filesystem::exists(dir / "v" / "mask.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "v" / "mask_check.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "v" / "truth.png"));
  EXPECT_EQ(read_image8(dir / "contact_sheet.png").width, 8 * 4);
}

// Written again without the internal image, the view keeps none of the earlier run's pictures
// of it, which would pass for this run's.
TEST(Diagnostics, PicturesThisRunLacksAreRemoved) {
  TempDir dir;
  const torch::Tensor gray = row_image({0.5f, 0.5f, 0.5f, 0.5f});
  write_diagnostics(dir.path(), {{"v", gray, gray, gray, torch::ones({1, 4}), gray}}, 0.6);
  ASSERT_TRUE(std::filesystem::exists(dir / "v" / "mask_check.png"));
  write_diagnostics(dir.path(), {{"v", gray, {}, gray, torch::ones({1, 4}), gray}}, 0.6);
  for (const char* picture : {"internal", "discrepancy", "mask", "mask_check"})
    EXPECT_FALSE(std::filesystem::exists(dir / "v" / (std::string(picture) + ".png"))) << picture;
  EXPECT_TRUE(std::filesystem::exists(dir / "v" / "external.png"));
  EXPECT_EQ(read_file(dir / "contact_sheet.html").find("mask.png"), std::string::npos);
}

}  // namespace
}  // namespace iesrgs::pipeline
