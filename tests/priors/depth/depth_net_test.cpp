#include "priors/depth/depth_net.hpp"

#include <gtest/gtest.h>

#include "support/expect_error.hpp"

namespace iesrgs::priors::depth {
namespace {

using testing::contains;
using testing::error_message;

const std::filesystem::path kTiny =
    std::filesystem::path(IESRGS_TEST_DATA) / "priors" / "depth" / "tiny.pth";

TEST(MakeDepthNet, NoneTurnsTheDepthPriorOff) {
  EXPECT_EQ(make_depth_net("none", ""), nullptr);
}

TEST(MakeDepthNet, UnknownModelIsNamed) {
  const std::string message = error_message([] { make_depth_net("midas", kTiny); });
  EXPECT_TRUE(contains(message, "unknown depth model 'midas'")) << message;
  EXPECT_TRUE(contains(error_message([] { make_depth_net("depth-anything-v2-vitg", kTiny); }),
                       "'depth-anything-v2-vitg'"));
}

TEST(MakeDepthNet, MissingWeightsNameTheExpectedCheckpoint) {
  const std::string message = error_message([] { make_depth_net("depth-anything-v2-vitb", ""); });
  EXPECT_TRUE(contains(message, "depth_anything_v2_vitb.pth")) << message;
  EXPECT_TRUE(contains(message, "--depth-weights")) << message;
}

TEST(MakeDepthNet, UnreadableOrForeignCheckpointsNameTheFile) {
  const std::filesystem::path missing = kTiny.parent_path() / "missing.pth";
  EXPECT_TRUE(contains(error_message([&] { make_depth_net("depth-anything-v2", missing); }),
                       missing.string()));
  // The fixture's tiny encoder is none of the released ones.
  const std::string message =
      error_message([] { make_depth_net("depth-anything-v2-vits", kTiny); });
  EXPECT_TRUE(contains(message, kTiny.string() + ": embedding width 24")) << message;
}

// The metric models share the relative ones' names and shapes but not their output: refused
// before anything is read, by the name the authors gave them.
TEST(MakeDepthNet, MetricCheckpointsAreRefusedByName) {
  const std::filesystem::path metric = "/nowhere/depth_anything_v2_metric_hypersim_vits.pth";
  const std::string message = error_message([&] { make_depth_net("depth-anything-v2", metric); });
  EXPECT_TRUE(contains(message, metric.string() + ": a Depth Anything V2 metric-depth checkpoint"))
      << message;
}

}  // namespace
}  // namespace iesrgs::priors::depth
