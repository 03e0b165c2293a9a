// Wall time of a stretch of work on one thread: std::chrono::steady_clock
// (clock_gettime(CLOCK_MONOTONIC), served by the vDSO on Linux: a memory read, not a system
// call). Any thread; no allocation; no errors.
#pragma once

#include <chrono>

namespace dpc {

/// Seconds from t0 to now on the steady clock.
inline double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace dpc
