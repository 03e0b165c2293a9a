// FrameProfile: where a propagation frame's wall time goes, stage by stage, as one duration
// histogram per stage (audio::CallbackStats: log-linear bins, quantiles within 6.25 %) and
// each stage's total. A live frame must fit its period (and the motion-to-sound latency
// target) whole, so this shows which stage to cut: the rays' tracing, the pairs' finishing
// (direct sound, edge diffraction, exact paths, the estimator's cache update), IR synthesis,
// partitioning (the convolver's FFTs of the new IRs), the hand-over to the audio thread, and
// the studio's snapshot copy.
//
// Threads: record() on the thread that runs the frames (one writer); snapshot() on any thread.
// Wait-free; no allocation (about 4 KB of atomics per stage, held by value). No errors.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "audio/callback_stats.h"

namespace dpc {

class FrameProfile {
 public:
  enum Stage : int {
    kTrace,      ///< tracing passes (Simulation::FrameTimes::trace)
    kPairs,      ///< pairs' finishing and the cache pool (FrameTimes::pairs + pool)
    kSynthesis,  ///< IR synthesis of the listener played (PropagationStage::prepare)
    kPartition,  ///< the convolver's partitions (FFTs) of the new IRs
    kPublish,    ///< acquiring an IR set and publishing it to the audio thread
    kSnapshot,   ///< the studio's copy of the frame (LiveSession::snapshot)
    kFrame,      ///< the whole frame, pose assembly and bookkeeping included
    kStages
  };
  /// The stage's name in JSON and status text ("trace", "pairs", ...).
  static const char* name(Stage s);

  /// One frame's time in stage s, seconds (>= 0).
  void record(Stage s, double seconds) noexcept;
  /// The CPU seconds of the pairs' parts, summed over pairs and threads (a pair's parts run
  /// on one tracing thread; pairs run concurrently): direct sound with edge diffraction,
  /// exact-path validation, estimator. Added to running totals.
  void recordPairCpu(double direct, double exact, double estimator) noexcept;

  struct Snapshot {
    std::array<audio::CallbackStats::Snapshot, kStages> stage{};
    std::array<double, kStages> totalSeconds{};
    double directCpuSeconds = 0.0, exactCpuSeconds = 0.0, estimatorCpuSeconds = 0.0;
    /// Mean seconds per recorded frame of stage s (0 before any).
    double meanSeconds(Stage s) const;
    /// One stage in milliseconds: frames recorded, mean, median, 95th percentile (each
    /// quantile high by at most one bin, 6.25 %) and the longest.
    struct Row {
      const char* name = "";
      uint64_t frames = 0;
      double meanMs = 0.0, medianMs = 0.0, p95Ms = 0.0, maxMs = 0.0;
    };
    /// Every stage's row, in Stage order (what --stats and dpc-bench print).
    std::array<Row, kStages> rows() const;
  };
  /// Any thread; copies about 30 KB; no allocation.
  Snapshot snapshot() const noexcept;

 private:
  std::array<audio::CallbackStats, kStages> stats_{};
  std::array<std::atomic<uint64_t>, kStages> totalNs_{};
  std::array<std::atomic<uint64_t>, 3> pairCpuNs_{};
};

}  // namespace dpc
