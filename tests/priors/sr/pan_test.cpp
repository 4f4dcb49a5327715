#include "priors/sr/pan.hpp"

#include <gtest/gtest.h>

#include "support/expect_error.hpp"

namespace iesrgs::priors::sr {
namespace {

TEST(Pan, UnsupportedScaleIsRejected) {
  const std::string message = iesrgs::testing::error_message([] {
    Pan(PanOptions{40, 24, 16, 5});
  });
  EXPECT_NE(message.find("scale 5"), std::string::npos) << message;
}

}  // namespace
}  // namespace iesrgs::priors::sr
