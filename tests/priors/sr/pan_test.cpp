#include "priors/sr/pan.hpp"

#include <gtest/gtest.h>

#include "priors/sr/sr_test_support.hpp"
#include "support/expect_error.hpp"

namespace iesrgs::priors::sr {
namespace {

using sr_testing::kReleasedWeights;
using sr_testing::parameter_count;
using sr_testing::released_fixture_error;
using sr_testing::tiny_fixture_error;

TEST(Pan, TinySeededConfigurationMatchesTheOfficialModule) {
  Pan net(PanOptions{8, 8, 2, 2});
  EXPECT_LT(tiny_fixture_error(net, "pan"), 1e-5);
}

TEST(Pan, DefaultConfigurationHasTheReleasedParameterCount) {
  Pan net;
  EXPECT_EQ(parameter_count(*net), 272419);
}

TEST(Pan, UnsupportedScaleIsRejected) {
  const std::string message = iesrgs::testing::error_message([] {
    Pan(PanOptions{40, 24, 16, 5});
  });
  EXPECT_NE(message.find("scale 5"), std::string::npos) << message;
}

TEST(Pan, ReleasedCheckpointMatchesTheOfficialModule) {
  const auto file = kReleasedWeights / "PAN_x4.pth";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not found (shared data absent)";
  EXPECT_LT(released_fixture_error("pan", file), 1e-4);
}

}  // namespace
}  // namespace iesrgs::priors::sr
