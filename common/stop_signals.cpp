#include "common/stop_signals.h"

#include <signal.h>
#include <time.h>

#include <atomic>
#include <cstdint>
#include <cstring>

namespace dpc {
namespace {

// Lock-free, so the handler may store them (async-signal-safe).
std::atomic<int> received{0};
std::atomic<int64_t> receivedNs{0};  ///< CLOCK_MONOTONIC of the first request
static_assert(std::atomic<int>::is_always_lock_free);
static_assert(std::atomic<int64_t>::is_always_lock_free);

/// A second request this soon after the first is the same one delivered twice (a terminal's
/// Ctrl-C to the whole job and mpirun forwarding it to its ranks; a shell passing on a hangup),
/// not a person asking again.
constexpr int64_t kRepeatNs = 250'000'000;

int64_t monotonicNs() {
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);  // async-signal-safe
  return int64_t(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

extern "C" void recordStopSignal(int signal) {
  int none = 0;
  const int64_t now = monotonicNs();
  if (received.compare_exchange_strong(none, signal, std::memory_order_relaxed)) {
    receivedNs.store(now, std::memory_order_relaxed);
    return;
  }
  // A person asking again (SIGINT or SIGTERM, a quarter of a second on) ends the process at
  // once by the signal's default action (both calls async-signal-safe). Not SIGPIPE (every
  // later write raises it again) nor SIGHUP (the terminal is gone: nobody asks twice).
  if (signal == SIGPIPE || signal == SIGHUP) return;
  if (now - receivedNs.load(std::memory_order_relaxed) < kRepeatNs) return;
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
