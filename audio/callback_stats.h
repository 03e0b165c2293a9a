// CallbackStats: counts and durations of an audio callback, written by the audio thread and read
// by a control thread (for a status line such as "audio-callback load (% of the block period)").
// Counters only grow; a control thread that wants windowed figures subtracts two snapshots
// (Snapshot::since). Durations are wall-clock nanoseconds, measured by the caller with
// std::chrono::steady_clock (clock_gettime(CLOCK_MONOTONIC), served by the vDSO on Linux
// x86-64 and arm64: a memory read, not a system call).
//
// Threads: record() on the audio thread (one writer); snapshot() and the Snapshot arithmetic on
// any thread. Allocation: none (a CallbackStats is ~4 KB of atomics, held by value). Errors:
// none.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace dpc::audio {

class CallbackStats {
 public:
  /// Histogram of callback durations: log-linear bins, 16 per octave (bin width <= 6.25 % of
  /// the value), exact below 32 ns, covering 0 .. 2^34 ns (17 s); longer durations land in
  /// the last bin.
  static constexpr int kBins = 512;

  /// Bin of a duration in ns, and the largest duration (ns) that falls in a bin. Any thread.
  static int binOf(uint64_t ns) noexcept;
  static uint64_t binUpperNs(int bin) noexcept;

  /// Records one callback of durationNs nanoseconds; xrun: the host reported an output
  /// underflow/overflow (or input under/overflow) for it. Audio thread. Wait-free: relaxed
  /// atomics only, no allocation, no system calls.
  void record(uint64_t durationNs, bool xrun) noexcept;

  /// A copy of the counters at one moment (not an atomic snapshot of all of them together:
  /// the audio thread may record one callback while it is being copied, which at most
  /// miscounts that one callback).
  struct Snapshot {
    uint64_t callbacks = 0;
    uint64_t xruns = 0;                       ///< callbacks flagged with an underflow or overflow
    uint64_t lastNs = 0;                      ///< duration of the most recent callback
    uint64_t maxNs = 0;                       ///< longest callback since the stream was opened
    std::array<uint64_t, kBins> histogram{};  ///< callbacks per duration bin

    /// Duration (ns) below which a fraction q in [0, 1] of the histogram's callbacks fall,
    /// given as the upper edge of the bin that holds the q-quantile, capped at maxNs (so it
    /// errs high by at most one bin width, 6.25 %). 0 if there are no callbacks. Any thread;
    /// no allocation.
    uint64_t quantileNs(double q) const noexcept;
    /// Mean duration (ns) of the histogram's callbacks, each counted at its bin's upper edge
    /// capped at maxNs (errs high by at most one bin width, 6.25 %). 0 if there are none.
    /// Any thread; no allocation.
    uint64_t meanNs() const noexcept;
    /// The counters accumulated after `earlier` (a snapshot of the same stats taken
    /// before): callbacks, xruns and histogram are differences, lastNs is this one's and
    /// maxNs is the upper edge of the highest non-empty bin of the difference. No allocation.
    Snapshot since(const Snapshot& earlier) const noexcept;
    /// The counters of two runs together (e.g. two streams of one session, one after the
    /// other): callbacks, xruns and histogram are sums, maxNs the larger, lastNs `later`'s.
    /// No allocation.
    Snapshot plus(const Snapshot& later) const noexcept;
  };
  /// Control thread (any thread). No allocation, wait-free; copies ~4 KB.
  Snapshot snapshot() const noexcept;

 private:
  std::atomic<uint64_t> callbacks_{0};
  std::atomic<uint64_t> xruns_{0};
  std::atomic<uint64_t> lastNs_{0};
  std::atomic<uint64_t> maxNs_{0};
  std::array<std::atomic<uint64_t>, kBins> histogram_{};
};

}  // namespace dpc::audio
