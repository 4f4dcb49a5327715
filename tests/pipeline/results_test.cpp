#include "pipeline/results.hpp"

#include <gtest/gtest.h>

#include <string>

#include "io/atomic_file.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs::pipeline {
namespace {

using testing::contains;

// An evaluated row and one without ground truth, with the stage times a run records.
RunResult sample_result() {
  RunResult result;
  RowResult scored{"ie-srgs", "IE-SRGS", {"mean", 26.68, 0.935, 0.1}, true, 12, 400};
  RowResult unscored{"internal", "internal only", {}, false, 103, 290.9};
  result.rows = {unscored, scored};
  result.stages = {{"external_seconds", 8},
                   {"internal_training_seconds", 103},
                   {"fusion_seconds", {{"ie-srgs", 12}}},
                   {"total_seconds_this_run", 130}};
  result.evaluation = {{"test_views", "digest"}, {"lpips", "alex"}};
  return result;
}

TEST(Results, WrittenRowsReadBackAsEarlierRows) {
  testing::TempDir dir;
  RunResult result = sample_result();
  result.rows[0].from_earlier_run = true;
  write_results(dir.path(), result);
  const nlohmann::json json = nlohmann::json::parse(read_file(dir / "results.json"));
  EXPECT_EQ(json["evaluation"]["test_views"], "digest");
  const RowResult back = earlier_row(*find_row("ie-srgs"), "IE-SRGS", json["rows"][1]);
  EXPECT_TRUE(back.from_earlier_run);
  EXPECT_TRUE(back.evaluated);
  EXPECT_DOUBLE_EQ(back.mean.psnr, 26.68);
  EXPECT_DOUBLE_EQ(back.mean.ssim, 0.935);
  ASSERT_TRUE(back.mean.lpips.has_value());
  EXPECT_DOUBLE_EQ(*back.mean.lpips, 0.1);
  EXPECT_DOUBLE_EQ(back.train_seconds, 12);
  EXPECT_DOUBLE_EQ(back.fps, 400);
  const RowResult unscored = earlier_row(*find_row("internal"), "internal", json["rows"][0]);
  EXPECT_FALSE(unscored.evaluated);
  EXPECT_FALSE(unscored.mean.lpips.has_value());
  EXPECT_EQ(read_file(dir / "results.csv"),
            "row,label,psnr,ssim,lpips,train_seconds,fps,from_earlier_run\n"
            "internal,\"internal only\",-,-,,103,290.9,true\n"
            "ie-srgs,\"IE-SRGS\",26.6800,0.93500,0.10000,12,400,false\n");
}

TEST(Results, MarkdownMarksEarlierRowsShowsDashesWithoutTruthAndTimesTheStages) {
  RunResult result = sample_result();
  result.rows[1].from_earlier_run = true;
  const std::string md = results_markdown(result);
  EXPECT_TRUE(contains(md, "| internal only | - | - | - | 1m43s | 290.9 |\n")) << md;
  EXPECT_TRUE(contains(md, "| IE-SRGS * | 26.68 | 0.9350 | 0.1000 | 12s | 400.0 |\n")) << md;
  EXPECT_TRUE(contains(md, "\\* from an earlier run in this folder with the same settings")) << md;
  EXPECT_TRUE(contains(md, "| external knowledge (E_image, E_depth) | 8s |\n")) << md;
  EXPECT_TRUE(contains(md, "| HR training, ie-srgs | 12s |\n")) << md;
  EXPECT_FALSE(contains(md, "HR training, internal")) << md;  // no time recorded for it
  EXPECT_TRUE(contains(md, "| this run in all | 2m10s |\n")) << md;
  result.rows[0].fps = 0;  // a scene without test views renders none
  EXPECT_TRUE(contains(results_markdown(result), "| internal only | - | - | - | 1m43s | - |\n"));
}

}  // namespace
}  // namespace iesrgs::pipeline
