#include "core/interrupt.hpp"

#include <time.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdint>

#include "core/error.hpp"

namespace iesrgs {

namespace {

std::atomic<int> received{0};  // the signal that asked, 0 while none did
std::atomic<int64_t> received_at_ns{0};
int open_scopes = 0;  // scopes are made by the main thread only

void (*exit_cleanup)() = nullptr;

int64_t monotonic_ns() {  // async-signal-safe
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);
  return int64_t(now.tv_sec) * 1000000000 + now.tv_nsec;
}

// The signal that asked, sent again at once: GNU timeout signals the process and then its
// process group, which holds it, so that its one stop arrives twice.
bool repeats_the_request(int signal) {
  return signal == received.load() &&
         monotonic_ns() - received_at_ns.load() < int64_t(kRepeatedSignalMs) * 1000000;
}

extern "C" void end_now(int signal) {
  if (repeats_the_request(signal)) return;
  if (exit_cleanup) exit_cleanup();
  static constexpr char kMessage[] =
      "\ninterrupted: stopped before the end; the files being written were removed\n";
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
  std::signal(signal, SIG_DFL);
  std::raise(signal);  // delivered as the handler returns: the process ends as the signal ends it
}

// Installs `handler` for `signal` and returns the one it replaces, but leaves a signal the caller
// ignores ignored: a shell starts a script's `command &` so, so that Ctrl-C reaches only the
// script's foreground.
void (*catch_signal(int signal, void (*handler)(int)))(int) {
  struct sigaction current {};
  if (::sigaction(signal, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) return SIG_IGN;
  return std::signal(signal, handler);
}

extern "C" void request_interrupt(int signal) {
  received_at_ns = monotonic_ns();
  received = signal;
  std::signal(signal, end_now);  // a second Ctrl-C stops at once
}

}  // namespace

InterruptScope::InterruptScope() {
  if (open_scopes++ == 0) received = 0;
  previous_int_ = catch_signal(SIGINT, request_interrupt);
  previous_term_ = catch_signal(SIGTERM, request_interrupt);
}

InterruptScope::~InterruptScope() {
  // Inside an outer scope after a request, the outer handlers would catch a second signal too.
  const bool asked_inside = interrupt_requested() && open_scopes > 1;
  std::signal(SIGINT, asked_inside ? end_now : previous_int_);
  std::signal(SIGTERM, asked_inside ? end_now : previous_term_);
  --open_scopes;
}

void end_on_signals(void (*cleanup)()) {
  exit_cleanup = cleanup;
  catch_signal(SIGINT, end_now);
  catch_signal(SIGTERM, end_now);
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
