#include "priors/sr/imdn.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "support/expect_error.hpp"

namespace iesrgs::priors::sr {
namespace {

TEST(Imdn, TooFewChannelsForTheAttentionAreRejected) {
  const std::string message = iesrgs::testing::error_message([] { Imdn(ImdnOptions{8, 4}); });
  EXPECT_NE(message.find("at least 16"), std::string::npos) << message;
}

// The authors' other releases, by the names that set their layouts apart (as in IMDN_AS.pth,
// model_RTC.pth and model_RTE.pth); the released x2/x3/x4 layout (tiny_imdn_x2.pth) passes.
TEST(Imdn, OtherReleasesAreRefusedByName) {
  using iesrgs::testing::error_message;
  const std::map<std::string, std::vector<std::string>> releases = {
      {"IMDN_AS", {"fea_conv.0.weight", "IMDB1.c1.weight"}},
      {"IMDN_RTC", {"model.0.weight", "model.1.sub.0.c1.weight"}},
      {"IMDN_RTE", {"fea_conv.0.weight", "block1.c1.weight"}}};
  for (const auto& [release, names] : releases) {
    StateDict weights;
    for (const std::string& name : names) weights[name] = torch::zeros({1});
    const std::string message = error_message([&] { check_imdn_release(weights, "other.pth"); });
    EXPECT_EQ(message.rfind("other.pth: an " + release + " ", 0), 0u) << message;
  }
  const auto tiny = std::filesystem::path(IESRGS_TEST_DATA) / "priors/sr/tiny_imdn_x2.pth";
  EXPECT_NO_THROW(check_imdn_release(read_state_dict(tiny), tiny));
}

}  // namespace
}  // namespace iesrgs::priors::sr
