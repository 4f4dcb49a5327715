// The instruction-set variant of the CPU kernels can be named and chosen.
#include "core/cpu_isa.hpp"

#include <gtest/gtest.h>

#include "support/active_isa.hpp"
#include "support/expect_error.hpp"

namespace iesrgs::cpu_isa {
namespace {

TEST(CpuIsa, BaselineCanAlwaysBeChosen) {
  EXPECT_TRUE(supported(Isa::kBaseline));
  const testing::ActiveIsa chosen(Isa::kBaseline);
  EXPECT_EQ(active(), Isa::kBaseline);
}

TEST(CpuIsa, NamesParseAndUnknownOnesAreErrors) {
  EXPECT_EQ(parse("baseline", "test"), Isa::kBaseline);
  EXPECT_EQ(parse("avx2", "test"), Isa::kAvx2);
  EXPECT_STREQ(name(Isa::kAvx2), "avx2");
  EXPECT_EQ(testing::error_message([] { parse("sse9", "IESRGS_CPU_ISA"); }),
            "IESRGS_CPU_ISA: unknown instruction set 'sse9' (expected baseline or avx2)");
}

}  // namespace
}  // namespace iesrgs::cpu_isa
