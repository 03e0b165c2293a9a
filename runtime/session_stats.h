// Statistics of a live session (docs/design.md "Runtime interfaces", "Statistics"): what the
// propagation thread measured of its last frame, what the audio thread counted, and the
// per-frame cache totals the offline renderer reports too. Counters are relaxed atomics, each
// written by one thread and read by the control thread at any time.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "audio/callback_stats.h"
#include "engine/simulation.h"
#include "runtime/max_order_warning.h"

namespace dpc {

/// One frame's cache and ray totals over a set of source-listener pairs. Any thread; no
/// allocation.
struct FrameTotals {
  uint64_t rays = 0;                ///< rays traced, summed
  size_t cacheEntries = 0;          ///< DPC path entries, summed
  size_t cacheCoarseEntries = 0;    ///< DPC coarse-store entries, summed
  size_t cacheBytes = 0;            ///< DPC heap bytes, summed
  size_t cacheBudgetBytes = 0;      ///< DPC memory budget: pairs' budgets summed, at most the pool
  size_t cachePoolUsedBytes = 0;    ///< DPC pool bytes held by all pairs
  uint64_t cachePoolRefusals = 0;   ///< table growths the full pool refused, summed
  size_t cachePairs = 0;            ///< source-listener pairs added
  size_t cachePairBytesMin = 0;     ///< smallest pair's DPC heap bytes (its pool use)
  size_t cachePairBytesMax = 0;     ///< largest pair's DPC heap bytes
  uint64_t cacheMergedEntries = 0;  ///< path entries merged by the budget, cumulative, summed
  double cacheCoarseEnergyFraction = 0;  ///< largest per-pair share of the response they carry
  /// Largest per-pair share of the estimator's energy that arrived beyond the IR length and
  /// was left out of the response (EnergyResponse::droppedEnergy(), summed over bands).
  double droppedEnergyFraction = 0;
  /// Largest per-pair, per-band share of the emitted energy that rays still carried when the
  /// reflection order bound (max_order) ended them (TraceStats::maxOrderEnergy / rays): lost
  /// to the response, most of it late (a raised max_order keeps it).
  double maxOrderEnergyFraction = 0;
  /// Ways round edges in series that the chains' caps left out of the direct sound's
  /// diffraction (DirectSound::chainsLeftOut, engine/edge_chain.h), summed over the pairs.
  uint64_t chainsLeftOut = 0;
  void add(const Simulation::SourceResult& r);
};

/// What LiveSession::status() reports. Plain values; any thread.
struct SessionStatus {
  uint64_t frames = 0;
  double frameMs = 0.0;        ///< last propagation frame (trace + synthesis + prepare)
  double raysPerSecond = 0.0;  ///< over the last status interval
  /// Rays per source traced by the last frame (0 before the first); below raysPerFrameScene
  /// when the adaptive controller reduced them to hold the frame rate.
  int raysPerFrame = 0;
  int raysPerFrameMin = 0;      ///< fewest rays per source of any frame so far (0: none yet)
  int raysPerFrameScene = 0;    ///< the settings' rays per source (the controller's ceiling)
  uint64_t reducedFrames = 0;   ///< frames traced with fewer rays than raysPerFrameScene
  /// The adaptive controller's floor (AdaptiveRays::floor) and the frames traced at or below
  /// it: frames whose budget the rays could not meet.
  int raysPerFrameFloor = 0;
  uint64_t floorFrames = 0;
  /// 5th percentile and median of the rays per source over all frames so far (the upper edge
  /// of a histogram bin: at most 6.25 % high; 0 before the first frame).
  int raysPerFrameP5 = 0, raysPerFrameMedian = 0;
  size_t cacheEntries = 0;      ///< DPC path + coarse entries, summed over sources
  size_t cacheBytes = 0;        ///< DPC heap bytes, summed over sources
  size_t cacheBudgetBytes = 0;  ///< DPC memory budget, summed over sources
  /// The cache pool's use per source-listener pair, last frame (played listener): pairs,
  /// smallest and largest pair's bytes, and the pool's bytes held by every pair of the engine.
  size_t cachePairs = 0, cachePairBytesMin = 0, cachePairBytesMax = 0, cachePoolUsedBytes = 0;
  uint64_t cacheMergedEntries = 0;         ///< entries merged into the coarse store, cumulative
  double cacheMergedEnergyFraction = 0.0;  ///< largest per-source share of the response they carry
  /// Last frame, played listener: largest per-source share of the energy that arrived beyond
  /// the IR length (not in the IR; FrameTotals::droppedEnergyFraction).
  double droppedEnergyFraction = 0.0;
  /// Last frame, played listener: largest per-source, per-band share of the emitted energy
  /// that rays still carried when max_order ended them (FrameTotals::maxOrderEnergyFraction).
  double maxOrderEnergyFraction = 0.0;
  /// The largest maxOrderEnergyFraction of any frame so far: what a warning read once a
  /// second acts on, so that a frame between two reads is not missed.
  double maxOrderEnergyFractionPeak = 0.0;
  /// Last frame, played listener: ways round edges in series the diffraction's caps left out,
  /// summed over the sources (FrameTotals::chainsLeftOut).
  uint64_t chainsLeftOut = 0;
  uint64_t irsApplied = 0;  ///< IR sets that reached the convolvers
  uint64_t irsDropped = 0;  ///< superseded before the audio thread applied them
  /// Frames that produced no IR set because every set was held by the audio side (0 unless
  /// the exchange's pool is too small: a bug worth reporting; runtime/ir_exchange.h).
  uint64_t irsLost = 0;
  /// Convolution partitions left out because a response's onset jumped past transforms the
  /// convolver had skipped (a teleport; NonUniformConvolver::stalePartitions).
  uint64_t stalePartitions = 0;
  double irAgeMs = 0.0;          ///< age of the IR playing, at the last block
  double latencyMedianMs = 0.0;  ///< motion-to-sound latency, since start
  double latencyP95Ms = 0.0;
  uint64_t blocks = 0;
  uint64_t nanBlocks = 0;  ///< blocks zeroed by the NaN/inf guard
  /// Host input samples (render() with inputs) replaced by 0: not finite, or beyond the
  /// +-1e6 a dry signal may hold (AudioStage::readHostInput).
  uint64_t inputSamplesReplaced = 0;
  uint64_t lateCallbacks = 0;      ///< render() calls that took longer than the audio they
                                   ///< produced (frames / sampleRate): a device would xrun
  /// The first kLateCallbacksKept late render() calls (min(lateCallbacks, kept) of them):
  /// when each started (seconds after start()) and how long it took (ms). Where they fall
  /// tells the session's own stalls (at start, at IR swaps) from the machine's.
  static constexpr int kLateCallbacksKept = 8;
  std::array<double, kLateCallbacksKept> lateCallbackAtSeconds{};
  std::array<double, kLateCallbacksKept> lateCallbackMs{};
  uint64_t rejectedCallbacks = 0;  ///< render() calls with frames outside the accepted range
  uint64_t recordDropped = 0;      ///< samples the recorder ring could not take
  /// Output safety limiter (audio/limiter.h), since start: frames it attenuated, frames
  /// whose input exceeded its ceiling, and its largest gain reduction (dB).
  uint64_t limitedFrames = 0;
  uint64_t overCeilingFrames = 0;
  float limiterMaxReductionDb = 0.f;
  /// Baked playback (runtime/baked_playback.h), since start; all 0 without a bake: source
  /// responses played from the bake, and frames whose listener saw no probe (played live).
  uint64_t bakedResponses = 0;
  uint64_t bakeFallbacks = 0;
  /// Time to first sound: from LiveSession::start() to the start of the first render() call
  /// whose output held a sample other than 0, seconds; NaN until then.
  double firstSoundSeconds = std::numeric_limits<double>::quiet_NaN();
  /// LiveSession::Options::quickFirstIr: the propagation thread's completion of the IR
  /// synthesisers after the first frame (the second frame waited for it), seconds; NaN before
  /// it, or when the session was built complete or completed by step().
  double synthesisCompletionSeconds = std::numeric_limits<double>::quiet_NaN();
  /// Options::measureFftPlans: 1 when FFTW could not measure the convolvers' plans in the
  /// background (the estimated plans stayed: the same sound, slower callbacks), else 0.
  uint64_t fftPlanFailures = 0;
};

/// The counters behind SessionStatus that the session's threads update. Propagation-side
/// methods: the propagation thread (or the control thread while it is stopped); audio-side
/// methods: the audio thread; read() and the getters: any thread. Wait-free; no allocation.
class SessionCounters {
 public:
  /// sceneRaysPerFrame: the settings' rays; floorRays: the adaptive controller's floor.
  SessionCounters(int sceneRaysPerFrame, int floorRays);

  /// Propagation side: rays per source the frame traced (every source the same).
  void raysTraced(int raysPerSource) noexcept;
  /// Propagation side: a frame produced an IR set; its totals and duration.
  void frameDone(const FrameTotals& totals, double frameMs) noexcept;
  /// Audio side: a block rendered (finite: false when the NaN guard zeroed it), the sets
  /// applied so far and the age of the one playing (ms; negative: none yet).
  void blockDone(bool finite, uint64_t irsApplied, double irAgeMs) noexcept;
  /// Audio side: a render() call that started at startNs (steady clock) took durationNs,
  /// longer than its audio; the first SessionStatus::kLateCallbacksKept are kept.
  void lateCallback(int64_t startNs, int64_t durationNs) noexcept;
  /// Audio side: host input samples replaced so far (a running total).
  void inputSamplesReplaced(uint64_t total) noexcept {
    inputSamplesReplaced_.store(total, std::memory_order_relaxed);
  }
  void rejectedCallback() noexcept { rejectedCallbacks_.fetch_add(1, std::memory_order_relaxed); }
  /// Propagation side: baked playback's cumulative counts (BakedPlayback::Stats).
  void bakeCounts(uint64_t bakedResponses, uint64_t fallbacks) noexcept {
    bakedResponses_.store(bakedResponses, std::memory_order_relaxed);
    bakeFallbacks_.store(fallbacks, std::memory_order_relaxed);
  }

  /// Control thread: the session starts now (steady clock, ns), before its threads do.
  void started(int64_t ns) noexcept { startedNs_.store(ns, std::memory_order_relaxed); }
  /// Audio side: whether a sound was heard yet; heard(ns): the first block with sound started
  /// at ns (steady clock; later calls change nothing).
  bool soundHeard() const noexcept { return firstSoundNs_.load(std::memory_order_relaxed) != 0; }
  void heard(int64_t ns) noexcept {
    int64_t none = 0;
    firstSoundNs_.compare_exchange_strong(none, ns, std::memory_order_relaxed);
  }

  /// Propagation side: the synthesisers' completion after the first frame took this long.
  void synthesisCompleted(double seconds) noexcept {
    completionSeconds_.store(seconds, std::memory_order_relaxed);
  }

  /// Planner thread: FFTW could not measure the convolvers' plans.
  void fftPlanFailed() noexcept { fftPlanFailures_.fetch_add(1, std::memory_order_relaxed); }

  uint64_t frames() const noexcept { return frames_.load(std::memory_order_relaxed); }
  /// Fills the counters' part of st; raysPerSecond over the time since the previous call.
  /// Control thread (one reader).
  void read(SessionStatus& st);

 private:
  const int sceneRays_, floorRays_;
  audio::CallbackStats raysStats_;  ///< rays per source per frame, as a histogram of "ns"
  std::atomic<uint64_t> frames_{0}, rays_{0}, blocks_{0}, nanBlocks_{0}, lateCallbacks_{0},
      rejectedCallbacks_{0}, irsApplied_{0}, reducedFrames_{0}, floorFrames_{0},
      cacheMergedEntries_{0}, bakedResponses_{0}, bakeFallbacks_{0}, inputSamplesReplaced_{0},
      fftPlanFailures_{0}, chainsLeftOut_{0};
  std::atomic<double> frameMs_{0.0}, irAgeMs_{0.0}, cacheMergedEnergyFraction_{0.0},
      droppedEnergyFraction_{0.0}, maxOrderEnergyFraction_{0.0}, maxOrderEnergyFractionPeak_{0.0};
  std::atomic<double> completionSeconds_{std::numeric_limits<double>::quiet_NaN()};
  std::atomic<size_t> cacheEntries_{0}, cacheBytes_{0}, cacheBudgetBytes_{0}, cachePairs_{0},
      cachePairBytesMin_{0}, cachePairBytesMax_{0}, cachePoolUsedBytes_{0};
  std::atomic<int> raysPerFrame_{0}, raysPerFrameMin_{0};
  std::atomic<int64_t> startedNs_{0}, firstSoundNs_{0};
  std::array<std::atomic<int64_t>, SessionStatus::kLateCallbacksKept> lateStartNs_{},
      lateDurationNs_{};
  uint64_t lastRays_ = 0;  ///< read()'s previous ray count
  std::chrono::steady_clock::time_point lastRead_;
};

}  // namespace dpc
