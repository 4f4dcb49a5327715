#include "core/interrupt.hpp"

#include <atomic>
#include <csignal>

#include "core/error.hpp"

namespace iesrgs {

namespace {

std::atomic<int> received{0};  // the signal that asked, 0 while none did
int open_scopes = 0;           // scopes are made by the main thread only

extern "C" void request_interrupt(int signal) {
  received = signal;
  std::signal(signal, SIG_DFL);  // a second Ctrl-C stops at once
}

}  // namespace

InterruptScope::InterruptScope() {
  if (open_scopes++ == 0) received = 0;
  previous_int_ = std::signal(SIGINT, request_interrupt);
  previous_term_ = std::signal(SIGTERM, request_interrupt);
}

InterruptScope::~InterruptScope() {
  // Inside an outer scope after a request, the outer handlers would catch a second signal too.
  const bool asked_inside = interrupt_requested() && open_scopes > 1;
  std::signal(SIGINT, asked_inside ? SIG_DFL : previous_int_);
  std::signal(SIGTERM, asked_inside ? SIG_DFL : previous_term_);
  --open_scopes;
}

bool interrupt_requested() {
  return received.load() != 0;
}

int interrupt_exit_status() {
  return 128 + (interrupt_requested() ? received.load() : SIGINT);
}

void stop_if_interrupted(const std::string& what) {
  if (interrupt_requested())
    throw Interrupted(what + " stopped; run the same command again to resume");
}

}  // namespace iesrgs
