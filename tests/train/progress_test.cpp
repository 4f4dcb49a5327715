#include "train/progress.hpp"

#include <gtest/gtest.h>

namespace iesrgs::train {
namespace {

TEST(Progress, DurationsReadAsHoursMinutesSeconds) {
  EXPECT_EQ(format_duration(42.4), "42s");
  EXPECT_EQ(format_duration(187), "3m07s");
  EXPECT_EQ(format_duration(3725), "1h02m05s");
  EXPECT_EQ(format_duration(-3), "0s");
}

TEST(Progress, EtaFollowsTheMeanPaceSoFar) {
  EXPECT_EQ(format_eta(2, 10, 30), "2m00s");  // 15 s each, 8 left
  EXPECT_EQ(format_eta(10, 10, 30), "0s");
  EXPECT_EQ(format_eta(0, 10, 0), "?");  // no pace yet
}

}  // namespace
}  // namespace iesrgs::train
