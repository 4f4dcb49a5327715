#include "priors/sr/imdn.hpp"

#include <gtest/gtest.h>

#include "priors/sr/sr_test_support.hpp"
#include "support/expect_error.hpp"

namespace iesrgs::priors::sr {
namespace {

using sr_testing::kReleasedWeights;
using sr_testing::parameter_count;
using sr_testing::released_fixture_error;
using sr_testing::tiny_fixture_error;

TEST(Imdn, TinySeededConfigurationMatchesTheOfficialModule) {
  Imdn net(ImdnOptions{16, 2});
  EXPECT_LT(tiny_fixture_error(net, "imdn"), 1e-5);
}

TEST(Imdn, DefaultConfigurationHasTheReleasedParameterCount) {
  Imdn net;
  EXPECT_EQ(parameter_count(*net), 715176);
}

TEST(Imdn, TooFewChannelsForTheAttentionAreRejected) {
  const std::string message = iesrgs::testing::error_message([] { Imdn(ImdnOptions{8, 4}); });
  EXPECT_NE(message.find("at least 16"), std::string::npos) << message;
}

TEST(Imdn, ReleasedCheckpointMatchesTheOfficialModule) {
  const auto file = kReleasedWeights / "IMDN_x4.pth";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not found (shared data absent)";
  EXPECT_LT(released_fixture_error("imdn", file), 1e-4);
}

}  // namespace
}  // namespace iesrgs::priors::sr
