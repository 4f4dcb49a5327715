// What every CNN super-resolution model of the development data must match: the authors' module
// in a tiny seeded configuration of the official layout, the released configuration's parameter
// count, and the released x4 checkpoint itself on a lego crop.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <functional>
#include <ostream>
#include <string>

#include "priors/sr/imdn.hpp"
#include "priors/sr/pan.hpp"
#include "priors/sr/safmn.hpp"
#include "priors/sr/sr_test_support.hpp"

namespace iesrgs::priors::sr {
namespace {

using sr_testing::kReleasedWeights;
using sr_testing::parameter_count;
using sr_testing::released_fixture_error;
using sr_testing::tiny_fixture_error;

struct SrModelCase {
  std::string model;  // the registry's name, which also names its fixtures
  std::function<float()> tiny_error;
  std::function<int64_t()> default_parameters;
  int64_t released_parameters;
};

// gtest lists a parameter by this, not by its bytes.
void PrintTo(const SrModelCase& c, std::ostream* out) {
  *out << c.model;
}

template <class Net, class Options>
SrModelCase model_case(const std::string& model, const Options& tiny, int64_t released_parameters) {
  return {model,
          [=] {
            Net net(tiny);
            return tiny_fixture_error(net, model);
          },
          [] {
            Net net;
            return parameter_count(*net);
          },
          released_parameters};
}

class SrModel : public ::testing::TestWithParam<SrModelCase> {};

TEST_P(SrModel, TinySeededConfigurationMatchesTheOfficialModule) {
  EXPECT_LT(GetParam().tiny_error(), 1e-5);
}

TEST_P(SrModel, DefaultConfigurationHasTheReleasedParameterCount) {
  EXPECT_EQ(GetParam().default_parameters(), GetParam().released_parameters);
}

TEST_P(SrModel, ReleasedCheckpointMatchesTheOfficialModule) {
  std::string upper = GetParam().model;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return char(std::toupper(c)); });
  const auto file = kReleasedWeights / (upper + "_x4.pth");
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " not found (shared data absent)";
  EXPECT_LT(released_fixture_error(GetParam().model, file), 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Cnn, SrModel,
                         ::testing::Values(model_case<Safmn>("safmn", SafmnOptions{8, 2, 2.0, 2},
                                                             237000),
                                           model_case<Imdn>("imdn", ImdnOptions{16, 2}, 715176),
                                           model_case<Pan>("pan", PanOptions{8, 8, 2, 2}, 272419)),
                         [](const auto& info) { return info.param.model; });

}  // namespace
}  // namespace iesrgs::priors::sr
