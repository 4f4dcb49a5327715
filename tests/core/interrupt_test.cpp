#include "core/interrupt.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <optional>

#include "core/error.hpp"
#include "support/expect_error.hpp"

namespace iesrgs {
namespace {

using testing::error_message;

TEST(Interrupt, ASignalInsideAScopeAsksTheWorkToStop) {
  const InterruptScope scope;
  EXPECT_FALSE(interrupt_requested());
  stop_if_interrupted("the external stage");  // nothing asked: goes on
  std::raise(SIGTERM);
  EXPECT_TRUE(interrupt_requested());
  EXPECT_EQ(interrupt_exit_status(), 128 + SIGTERM);  // 143, as if the signal had ended it
  EXPECT_THROW(stop_if_interrupted("rendering"), Interrupted);
  EXPECT_EQ(error_message([] { stop_if_interrupted("rendering"); }),
            "rendering stopped; run the same command again to resume");
}

// The trainer's scope inside a run's: a Ctrl-C the run got before training began still counts.
TEST(Interrupt, AnInnerScopeKeepsTheOuterScopesRequest) {
  std::optional<InterruptScope> outer(std::in_place);
  std::raise(SIGINT);
  {
    const InterruptScope inner;
    EXPECT_TRUE(interrupt_requested());
    EXPECT_EQ(interrupt_exit_status(), 128 + SIGINT);
  }
  // A second signal would now end the process, not be caught by the outer scope's handler.
  EXPECT_EQ(std::signal(SIGINT, SIG_DFL), SIG_DFL);
  outer.reset();
  const InterruptScope next;  // a new outermost scope starts afresh
  EXPECT_FALSE(interrupt_requested());
}

}  // namespace
}  // namespace iesrgs
