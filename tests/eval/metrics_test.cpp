#include "eval/metrics.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/atomic_file.hpp"
#include "loss/loss_test_support.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::eval {
namespace {

using testing::contains;

Image filled(int width, int height, float value) {
  Image image(width, height, 3);
  std::fill(image.data.begin(), image.data.end(), value);
  return image;
}

TEST(Metrics, PsnrIsOfTheMeanSquaredErrorOverEveryChannel) {
  EXPECT_NEAR(psnr(filled(4, 3, 0.5f), filled(4, 3, 0.6f)), 20.0, 1e-5);
  Image one_off = filled(4, 3, 0.5f);
  one_off.data[7] = 0.8f;  // mse 0.09 / 36
  EXPECT_NEAR(psnr(one_off, filled(4, 3, 0.5f)), -10 * std::log10(0.09 / 36), 1e-4);
  EXPECT_TRUE(std::isinf(psnr(filled(4, 3, 0.5f), filled(4, 3, 0.5f))));
}

TEST(Metrics, SsimIsOneOnlyForIdenticalImages) {
  Image noisy = filled(16, 16, 0.5f);
  for (size_t i = 0; i < noisy.data.size(); ++i) noisy.data[i] = float(i % 7) / 7;
  EXPECT_NEAR(ssim(noisy, noisy), 1.0, 1e-6);
  EXPECT_LT(ssim(noisy, filled(16, 16, 0.5f)), 0.5);
}

// The metric reads interleaved images: on a non-square image whose channels differ, it is the
// channel mean of 3DGS's SSIM (the loss tests' float64 reference) of the planes.
TEST(Metrics, SsimIsTheChannelMeanOfThePlanes) {
  const int width = 21, height = 13;
  const std::vector<double> x = loss_testing::random_values(size_t(width) * height * 3, 5),
                            y = loss_testing::random_values(x.size(), 6);
  Image a(width, height, 3), b(width, height, 3);
  std::vector<double> x_planes(x.size()), y_planes(x.size());
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < height; ++row)
      for (int col = 0; col < width; ++col) {
        // Each channel's own blend of the two, so that mixing channels up changes the score.
        const size_t i = (size_t(c) * height + row) * width + col;
        x_planes[i] = a.at(col, row, c) = float(x[i]);
        y_planes[i] = b.at(col, row, c) = float((c * x[i] + (2 - c) * y[i]) / 2);
      }
  const double expected =
      loss_testing::mean(loss_testing::reference_ssim_map(x_planes, y_planes, {width, height, 3}));
  EXPECT_NEAR(ssim(a, b), expected, 1e-5);
}

TEST(Metrics, ImagesOfOtherSizesOrChannelsAreRefused) {
  EXPECT_TRUE(contains(testing::error_message([] { psnr(filled(4, 3, 0), filled(3, 4, 0)); }),
                       "image is 4x3 but its reference is 3x4"));
  EXPECT_TRUE(contains(testing::error_message([] { ssim(Image(4, 4, 1), filled(4, 4, 0)); }),
                       "metrics need RGB images"));
}

TEST(Metrics, MeanHasLpipsOnlyWhenEveryViewHasIt) {
  MetricsReport report;
  report.views = {{"a", 20, 0.8, 0.1}, {"b", 30, 0.9, 0.3}};
  const ViewMetrics mean = report.mean();
  EXPECT_EQ(mean.name, "mean");
  EXPECT_DOUBLE_EQ(mean.psnr, 25);
  EXPECT_DOUBLE_EQ(mean.ssim, 0.85);
  ASSERT_TRUE(mean.lpips.has_value());
  EXPECT_DOUBLE_EQ(*mean.lpips, 0.2);
  report.views[1].lpips.reset();
  EXPECT_FALSE(report.mean().lpips.has_value());
  EXPECT_FALSE(MetricsReport{}.mean().lpips.has_value());
}

// JSON has no infinity: a perfect view's PSNR is null there, "inf" in the CSV.
TEST(Metrics, ReportWritesAnInfinitePsnrAsNullInJsonAndInfInCsv) {
  testing::TempDir dir;
  MetricsReport report;
  report.views = {{"same", INFINITY, 1, std::nullopt}, {"other", 20, 0.5, std::nullopt}};
  report.lpips_status = "none";
  write_report(dir / "metrics", report);
  const nlohmann::json json = nlohmann::json::parse(read_file(dir / "metrics.json"));
  EXPECT_TRUE(json["views"][0]["psnr"].is_null());
  EXPECT_EQ(json["views"][1]["psnr"], 20);
  EXPECT_TRUE(json["mean"]["psnr"].is_null());
  EXPECT_TRUE(json["mean"]["lpips"].is_null());
  EXPECT_EQ(json["lpips"], "none");
  EXPECT_EQ(read_file(dir / "metrics.csv"),
            "name,psnr,ssim,lpips\nsame,inf,1.000000,\nother,20.000000,0.500000,\n"
            "mean,inf,0.750000,\n");
}

// File names may hold commas and quotes; each row keeps four fields.
TEST(Metrics, CsvQuotesViewNamesThatNeedIt) {
  testing::TempDir dir;
  MetricsReport report;
  report.views = {{"a,b", 20, 0.5, std::nullopt}, {"say \"hi\"", 20, 0.5, std::nullopt}};
  write_report(dir / "metrics", report);
  EXPECT_EQ(read_file(dir / "metrics.csv"),
            "name,psnr,ssim,lpips\n\"a,b\",20.000000,0.500000,\n"
            "\"say \"\"hi\"\"\",20.000000,0.500000,\nmean,20.000000,0.500000,\n");
}

// A report whose CSV cannot be written (a folder holds its temporary's name, as a full disk would
// refuse it) leaves neither file, and not the earlier report either: never one beside the other.
TEST(Metrics, AReportThatCannotBeWrittenLeavesNeitherFile) {
  testing::TempDir dir;
  MetricsReport report;
  report.views = {{"view", 20, 0.5, std::nullopt}};
  write_report(dir / "metrics", report);
  report.views[0].psnr = 30;
  std::filesystem::create_directory(dir / ("metrics.csv.tmp-" + std::to_string(::getpid())));
  EXPECT_ANY_THROW(write_report(dir / "metrics", report));
  EXPECT_FALSE(std::filesystem::exists(dir / "metrics.json"));
  EXPECT_FALSE(std::filesystem::exists(dir / "metrics.csv"));
}

}  // namespace
}  // namespace iesrgs::eval
