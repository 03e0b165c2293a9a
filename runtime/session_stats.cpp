#include "runtime/session_stats.h"

#include <algorithm>

namespace dpc {

void FrameTotals::add(const Simulation::SourceResult& r) {
  rays += r.trace.rays;
  cacheEntries += r.cacheEntries;
  cacheCoarseEntries += r.cacheCoarseEntries;
  cacheBytes += r.cacheBytes;
  cacheBudgetBytes += r.cacheBudgetBytes;
  if (r.cachePoolBytes > 0) cacheBudgetBytes = std::min(cacheBudgetBytes, r.cachePoolBytes);
  cachePoolUsedBytes = std::max(cachePoolUsedBytes, r.cachePoolUsedBytes);
  cachePoolRefusals += r.cachePoolRefusals;
  cachePairBytesMin = cachePairs == 0 ? r.cacheBytes : std::min(cachePairBytesMin, r.cacheBytes);
  cachePairBytesMax = std::max(cachePairBytesMax, r.cacheBytes);
  ++cachePairs;
  cacheMergedEntries += r.cacheMergedEntries;
  chainsLeftOut += r.direct.chainsLeftOut;
  cacheCoarseEnergyFraction = std::max(cacheCoarseEnergyFraction, r.cacheCoarseEnergyFraction);
  const double dropped = double(r.energy.droppedEnergy().sum());
  const double kept = double(r.energy.total().sum());
  if (dropped > 0.0)
    droppedEnergyFraction = std::max(droppedEnergyFraction, dropped / (dropped + kept));
  maxOrderEnergyFraction = std::max(maxOrderEnergyFraction, r.trace.maxOrderShare());
}

SessionCounters::SessionCounters(int sceneRaysPerFrame, int floorRays)
    : sceneRays_(sceneRaysPerFrame),
      floorRays_(floorRays),
      lastRead_(std::chrono::steady_clock::now()) {}

void SessionCounters::raysTraced(int traced) noexcept {
  raysPerFrame_.store(traced, std::memory_order_relaxed);
  const int low = raysPerFrameMin_.load(std::memory_order_relaxed);
  if (low == 0 || traced < low) raysPerFrameMin_.store(traced, std::memory_order_relaxed);
  if (traced < sceneRays_) reducedFrames_.fetch_add(1, std::memory_order_relaxed);
  if (traced <= floorRays_ && traced < sceneRays_)
    floorFrames_.fetch_add(1, std::memory_order_relaxed);
  raysStats_.record(uint64_t(std::max(0, traced)), false);
}

void SessionCounters::frameDone(const FrameTotals& t, double frameMs) noexcept {
  frames_.fetch_add(1, std::memory_order_relaxed);
  rays_.fetch_add(t.rays, std::memory_order_relaxed);
  cacheEntries_.store(t.cacheEntries + t.cacheCoarseEntries, std::memory_order_relaxed);
  cacheBytes_.store(t.cacheBytes, std::memory_order_relaxed);
  cachePairs_.store(t.cachePairs, std::memory_order_relaxed);
  cachePairBytesMin_.store(t.cachePairBytesMin, std::memory_order_relaxed);
  cachePairBytesMax_.store(t.cachePairBytesMax, std::memory_order_relaxed);
  cachePoolUsedBytes_.store(t.cachePoolUsedBytes, std::memory_order_relaxed);
  cacheBudgetBytes_.store(t.cacheBudgetBytes, std::memory_order_relaxed);
  cacheMergedEntries_.store(t.cacheMergedEntries, std::memory_order_relaxed);
  cacheMergedEnergyFraction_.store(t.cacheCoarseEnergyFraction, std::memory_order_relaxed);
  droppedEnergyFraction_.store(t.droppedEnergyFraction, std::memory_order_relaxed);
  maxOrderEnergyFraction_.store(t.maxOrderEnergyFraction, std::memory_order_relaxed);
  // One writer (the propagation thread), so a load and a store keep the maximum.
  if (t.maxOrderEnergyFraction > maxOrderEnergyFractionPeak_.load(std::memory_order_relaxed))
    maxOrderEnergyFractionPeak_.store(t.maxOrderEnergyFraction, std::memory_order_relaxed);
  chainsLeftOut_.store(t.chainsLeftOut, std::memory_order_relaxed);
  frameMs_.store(frameMs, std::memory_order_relaxed);
}

void SessionCounters::blockDone(bool finite, uint64_t irsApplied, double irAgeMs) noexcept {
  if (!finite) nanBlocks_.fetch_add(1, std::memory_order_relaxed);
  if (irAgeMs >= 0.0) irAgeMs_.store(irAgeMs, std::memory_order_relaxed);
  irsApplied_.store(irsApplied, std::memory_order_relaxed);
  blocks_.fetch_add(1, std::memory_order_relaxed);
}

void SessionCounters::read(SessionStatus& st) {
  constexpr auto r = std::memory_order_relaxed;
  st.frames = frames_.load(r);
  st.frameMs = frameMs_.load(r);
  const auto now = std::chrono::steady_clock::now();
  const uint64_t rays = rays_.load(r);
  const double dt = std::chrono::duration<double>(now - lastRead_).count();
  st.raysPerSecond = dt > 0.0 ? double(rays - lastRays_) / dt : 0.0;
  lastRays_ = rays;
  lastRead_ = now;
  st.raysPerFrame = raysPerFrame_.load(r);
  st.raysPerFrameMin = raysPerFrameMin_.load(r);
  st.raysPerFrameScene = sceneRays_;
  st.reducedFrames = reducedFrames_.load(r);
  st.raysPerFrameFloor = floorRays_;
  st.floorFrames = floorFrames_.load(r);
  const audio::CallbackStats::Snapshot perFrame = raysStats_.snapshot();
  st.raysPerFrameP5 = int(perFrame.quantileNs(0.05));
  st.raysPerFrameMedian = int(perFrame.quantileNs(0.5));
  st.cacheEntries = cacheEntries_.load(r);
  st.cacheBytes = cacheBytes_.load(r);
  st.cachePairs = cachePairs_.load(r);
  st.cachePairBytesMin = cachePairBytesMin_.load(r);
  st.cachePairBytesMax = cachePairBytesMax_.load(r);
  st.cachePoolUsedBytes = cachePoolUsedBytes_.load(r);
  st.cacheBudgetBytes = cacheBudgetBytes_.load(r);
  st.cacheMergedEntries = cacheMergedEntries_.load(r);
  st.cacheMergedEnergyFraction = cacheMergedEnergyFraction_.load(r);
  st.droppedEnergyFraction = droppedEnergyFraction_.load(r);
  st.maxOrderEnergyFraction = maxOrderEnergyFraction_.load(r);
  st.maxOrderEnergyFractionPeak = maxOrderEnergyFractionPeak_.load(r);
  st.chainsLeftOut = chainsLeftOut_.load(r);
  st.irsApplied = irsApplied_.load(r);
  if (const int64_t heard = firstSoundNs_.load(r); heard != 0)
    st.firstSoundSeconds = double(heard - startedNs_.load(r)) * 1e-9;
  st.synthesisCompletionSeconds = completionSeconds_.load(r);
  st.fftPlanFailures = fftPlanFailures_.load(r);
  st.irAgeMs = irAgeMs_.load(r);
  st.bakedResponses = bakedResponses_.load(r);
  st.bakeFallbacks = bakeFallbacks_.load(r);
  st.blocks = blocks_.load(r);
  st.nanBlocks = nanBlocks_.load(r);
  st.inputSamplesReplaced = inputSamplesReplaced_.load(r);
  st.lateCallbacks = lateCallbacks_.load(std::memory_order_acquire);
  const uint64_t kept = std::min<uint64_t>(st.lateCallbacks, SessionStatus::kLateCallbacksKept);
  for (size_t i = 0; i < kept; ++i) {
    st.lateCallbackAtSeconds[i] = double(lateStartNs_[i].load(r) - startedNs_.load(r)) * 1e-9;
    st.lateCallbackMs[i] = double(lateDurationNs_[i].load(r)) * 1e-6;
  }
  st.rejectedCallbacks = rejectedCallbacks_.load(r);
}

void SessionCounters::lateCallback(int64_t startNs, int64_t durationNs) noexcept {
  const uint64_t index = lateCallbacks_.load(std::memory_order_relaxed);
  if (index < uint64_t(SessionStatus::kLateCallbacksKept)) {
    lateStartNs_[index].store(startNs, std::memory_order_relaxed);
    lateDurationNs_[index].store(durationNs, std::memory_order_relaxed);
  }
  // Published after its entry, so a reader that sees the count sees the entry (one writer).
  lateCallbacks_.fetch_add(1, std::memory_order_release);
}

}  // namespace dpc
