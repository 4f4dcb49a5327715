#include "priors/sr/imdn.hpp"

#include <gtest/gtest.h>

#include "support/expect_error.hpp"

namespace iesrgs::priors::sr {
namespace {

TEST(Imdn, TooFewChannelsForTheAttentionAreRejected) {
  const std::string message = iesrgs::testing::error_message([] { Imdn(ImdnOptions{8, 4}); });
  EXPECT_NE(message.find("at least 16"), std::string::npos) << message;
}

}  // namespace
}  // namespace iesrgs::priors::sr
