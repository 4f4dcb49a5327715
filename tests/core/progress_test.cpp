#include "core/progress.hpp"

#include <gtest/gtest.h>

#include <string>

namespace iesrgs {
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

TEST(Progress, ItemPaceGivesTheItemsSecondsAndTheEta) {
  ItemPace pace(2);
  const std::string first = pace.finished(1), last = pace.finished(2);
  EXPECT_NE(first.find(" s, ETA "), std::string::npos) << first;
  const std::string end = " s, ETA 0s";  // nothing left after the last item
  ASSERT_GT(last.size(), end.size());
  EXPECT_EQ(last.substr(last.size() - end.size()), end);
  EXPECT_EQ(last.find('.'), last.size() - end.size() - 3) << "two decimals: " << last;
  EXPECT_GE(std::stod(last), 0.0);
}

}  // namespace
}  // namespace iesrgs
