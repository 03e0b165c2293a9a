#include "common/stop_signals.h"

#include <signal.h>

#include <atomic>
#include <cstring>

namespace dpc {
namespace {

// Lock-free, so the handler may store it (async-signal-safe).
std::atomic<int> received{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void recordStopSignal(int signal) {
  int none = 0;
  if (received.compare_exchange_strong(none, signal, std::memory_order_relaxed)) return;
  // A second request (not a reader gone: every later write raises SIGPIPE again) ends the
  // process at once, as the user asks, by the signal's default action (both calls are
  // async-signal-safe).
  if (signal == SIGPIPE) return;
  ::signal(signal, SIG_DFL);
  ::raise(signal);
}

std::string signalName(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    case SIGPIPE:
      return "SIGPIPE";
    default:
      return "signal " + std::to_string(signal);
  }
}

}  // namespace

Interrupted::Interrupted(int signal)
    : std::runtime_error("interrupted by " + signalName(signal)), signal_(signal) {}

void catchStopSignals() {
  struct sigaction action {};
  action.sa_handler = recordStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // blocking reads and writes resume; the run checks the flag
  for (const int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE})
    if (sigaction(s, &action, nullptr) != 0)
      throw std::runtime_error("cannot install a handler for " + signalName(s) + ": " +
                               std::strerror(errno));
}

int stopSignal() noexcept {
  return received.load(std::memory_order_relaxed);
}

void throwIfStopped() {
  if (const int s = stopSignal()) throw Interrupted(s);
}

}  // namespace dpc
