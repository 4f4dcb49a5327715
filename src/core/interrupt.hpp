#pragma once
// SIGINT (Ctrl-C) and SIGTERM (kill, timeout, docker stop) ask long work to stop at its next safe
// point, while an InterruptScope is alive; outside one they end the process as the signal does
// (after end_on_signals' cleanup, once it is set). A second signal ends it at once, unless it is
// the first one again within kRepeatedSignalMs (timeout sends its one stop twice).
#include <string>

namespace iesrgs {

// How long the signal that asked to stop counts as the same request when it comes again.
constexpr int kRepeatedSignalMs = 250;

// Catches the two signals for its lifetime. Scopes nest: an inner one keeps a request the outer
// one received, and each gives the handlers back as it found them.
class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

 private:
  void (*previous_int_)(int);
  void (*previous_term_)(int);
};

// From now on a signal that no InterruptScope catches, and a second one inside a scope, ends the
// process as the signal would (status 130 or 143), after `cleanup` and a line on stderr saying so.
// `cleanup` runs in the signal handler: it may only make async-signal-safe calls. A signal the
// process was started ignoring (a script's `command &`) stays ignored, here and by the scopes.
void end_on_signals(void (*cleanup)());

// Whether a signal asked the work to stop.
bool interrupt_requested();

// The shell's status for a process the signal ended: 130 for SIGINT, 143 for SIGTERM.
int interrupt_exit_status();

// Throws Interrupted("<what> stopped; run the same command again to resume") when one did.
void stop_if_interrupted(const std::string& what);

}  // namespace iesrgs
