#include "core/interrupt.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <thread>

#include "core/error.hpp"
#include "support/child_process.hpp"
#include "support/expect_error.hpp"
#include "support/temp_dir.hpp"

namespace iesrgs {
namespace {

using testing::ended_by;
using testing::error_message;

// Past the time within which the signal that asked counts as the same request again.
void wait_past_repeats() {
  std::this_thread::sleep_for(std::chrono::milliseconds(kRepeatedSignalMs + 50));
}

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

// Outside a scope, a signal ends the process as it would have, after the cleanup; inside one, only
// a second signal does, also after leaving a nested scope. A signal ignored from the start stays
// ignored.
TEST(Interrupt, EndOnSignalsEndsTheProcessAfterTheCleanup) {
  static char marker[256];
  testing::TempDir dir;
  std::snprintf(marker, sizeof marker, "%s", (dir / "marker").c_str());
  const auto cleaned_up = [&](const std::function<void()>& work, int signal) {
    std::FILE* file = std::fopen(marker, "w");
    if (file) std::fclose(file);
    EXPECT_EQ(ended_by([&] {
                end_on_signals([] { ::unlink(marker); });
                work();
              }),
              signal);
    return !std::filesystem::exists(marker);
  };
  wait_past_repeats();  // an earlier test's request, which a signal now would repeat
  EXPECT_TRUE(cleaned_up([] { std::raise(SIGTERM); }, SIGTERM));
  EXPECT_TRUE(cleaned_up(
      [] {
        const InterruptScope scope;
        std::raise(SIGTERM);  // asks
        if (!interrupt_requested()) ::_exit(3);
        wait_past_repeats();
        std::raise(SIGTERM);  // ends
      },
      SIGTERM));
  // The same stop sent again at once (as timeout sends it) is the same request: work goes on.
  EXPECT_FALSE(cleaned_up(
      [] {
        const InterruptScope scope;
        std::raise(SIGTERM);
        std::raise(SIGTERM);
      },
      0));
  EXPECT_TRUE(cleaned_up(
      [] {
        const InterruptScope outer;
        {
          const InterruptScope inner;
          std::raise(SIGINT);
        }
        wait_past_repeats();
        std::raise(SIGINT);  // the second, after the inner scope gave its handler back
      },
      SIGINT));
  EXPECT_FALSE(cleaned_up(
      [] {
        std::signal(SIGINT, SIG_IGN);  // as a shell starts `command &` in a script
        end_on_signals([] { ::unlink(marker); });
        const InterruptScope scope;
        std::raise(SIGINT);
        if (interrupt_requested()) ::_exit(3);
      },
      0));
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
  wait_past_repeats();
  EXPECT_EQ(ended_by([] { std::raise(SIGINT); }), SIGINT);
  outer.reset();
  const InterruptScope next;  // a new outermost scope starts afresh
  EXPECT_FALSE(interrupt_requested());
}

}  // namespace
}  // namespace iesrgs
