// Estimators that turn one frame's listener hits into an energy response: plain Monte Carlo
// path tracing and the diffuse path cache (DPC) of Schissler's thesis, section 3.2.2.
//
// Both see the frame's hits grouped by path identifier (FrameGroups, engine/frame_groups.h).
// - PathTracingEstimator: every group adds I_f / N at delay (r_f / eta_f) / c, nothing is
//   kept between frames.
// - DiffusePathCache: entries persist across frames, weighted over time in one of three ways,
//   each a type of its own chosen once at construction (engine/path_cache_weightings.h), over
//   one store of path tables, coarse store and budget (engine/path_cache_store.h):
//   kSeed is the thesis: eq. 3.4 update, eq. 3.2 I_bar = I_hat / mu, eq. 3.3 r_bar = r_hat /
//   eta, removal after tau. kEma is dpc's unbiased variant: each entry keeps an exponential
//   moving average (time constant tau) of its per-frame estimate I_f / N, decayed every frame
//   whether hit or not, normalised by 1 - (1-a)^(n+1) for the n+1 frames since the cache
//   started, and dropped once its weight falls below kEmaDropFraction (docs/estimators.md has
//   the derivation and the measurements). kWindow: each entry holds the sums of its per-frame
//   estimates over the last W = round(tau / T) frames (at least 1) and reads out their mean,
//   sum / min(frames so far, W); each frame's contributions are kept in a ring of W frames and
//   subtracted when they leave the window; an entry with no hit left in the window is removed.
//   Unbiased for a static scene, and a step is answered completely W frames later.
// With tau = 0 every weighting reduce to PathTracingEstimator, bit for bit (the same float
// operations in the same order); tests/engine/path_cache_test.cpp checks it.
// Propagation thread only. Allocation: FrameGroups grows as needed, then keeps its capacity;
// DiffusePathCache starts with tables of kInitialTableBytes and doubles them while its paths
// need room, up to its budget and as far as its CachePool (engine/cache_pool.h) gives the bytes;
// only then does it merge entries into its coarse store. Errors: the constructor and capacityFor
// throw std::invalid_argument on bad settings; nothing else throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "engine/cache_pool.h"
#include "engine/energy_response.h"
#include "engine/frame_groups.h"
#include "engine/path_cache_store.h"
#include "scene/scene.h"

namespace dpc {

/// Plain Monte Carlo path tracing: no memory between frames.
class PathTracingEstimator {
 public:
  /// Adds every group's I_f / N at delay (r_f / eta_f) / c to out. N = rays emitted this frame.
  /// directional (optional): also receives every contribution with its arrival direction.
  void endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                EnergyResponse& out, ArrivalSink* directional = nullptr) const;
};

/// The diffuse path cache of one source-listener pair: its limits and budget split
/// (PathCacheLimits, engine/path_cache_store.h) and the store of the weighting chosen at
/// construction (engine/path_cache_weightings.h).
class DiffusePathCache : public PathCacheLimits {
 public:
  /// tauSeconds >= 0: cache response time; framePeriodSeconds > 0; budgetBytes: the most heap
  /// the cache may hold, never exceeded. The coarse store is allocated for the whole budget at
  /// construction (its pages are committed by the OS only as merges write them); the path
  /// tables start at kInitialTableBytes and double when full, each growth taking its bytes from
  /// `pool` (optional; it must outlive the cache) and allocating on the calling thread. When a
  /// table is full and cannot grow (budget reached or pool refusing), the oldest path entries (by
  /// creation for kSeed, by last hit for kEma and kWindow) are merged into the coarse store
  /// instead of dropped: per delay bin (1 ms, doubling when a delay does not fit) and, for kSeed,
  /// per creation frame, for kWindow per frame of the window. A coarse cell's state is the sum
  /// of its members' states, and every weighting's readout is linear in the state, so a merge
  /// changes the response's energy only by float rounding; the cost is delay resolution (1 ms:
  /// the hit-weighted mean delay; wider: spread evenly over the bin) and arrival direction
  /// (intensity-weighted mean). docs/estimators.md. Throws std::invalid_argument on bad
  /// arguments (see capacityFor). Allocates.
  DiffusePathCache(DpcWeighting weighting, double tauSeconds, double framePeriodSeconds,
                   size_t budgetBytes = kDefaultBudgetBytes, CachePool* pool = nullptr);
  ~DiffusePathCache();
  DiffusePathCache(const DiffusePathCache&) = delete;
  DiffusePathCache& operator=(const DiffusePathCache&) = delete;

  /// One frame: applies the frame's groups (eq. 3.4, the EMA or the window), reads out every
  /// entry and coarse cell into out, then removes expired entries. directional (optional):
  /// also receives every estimate with its mean arrival direction (intensity-weighted over
  /// the entry's hits). Allocates only when its tables grow.
  void endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                EnergyResponse& out, ArrivalSink* directional = nullptr);

  /// Forgets every path, coarse cell and frame (the tables keep their size).
  void clear();
  /// Path entries (coarse cells not included).
  size_t entryCount() const;
  /// Non-empty coarse-store cells (delay bins per layer holding merged energy).
  size_t coarseEntryCount() const;
  /// Most path entries the current tables hold (the budget's at most).
  size_t maxEntries() const;
  /// The budget, bytes.
  size_t budgetBytes() const;
  /// Heap bytes held by the cache's tables now (they grow as paths need room), <= budgetBytes().
  size_t bytes() const;
  /// Table growths the pool refused, also when retried between frames (the cache merged
  /// instead), since construction.
  uint64_t refusedGrowths() const;
  /// Between frames, on the thread that runs them: retries a growth the pool refused during
  /// the last frame (CachePool's frame shares; PathCacheStore::growDeferred). Allocates when
  /// it grows.
  void growDeferred();
  /// Heap bytes of the slots in use (entries, index load, window terms, coarse cells).
  size_t bytesInUse() const;
  /// Coarse-store layout: delays below S ms in 1 ms bins, then S bins per octave (each octave
  /// [S 2^k, S 2^(k+1)) ms in bins of 2^k ms). S starts at the largest power of two <= the
  /// bins per layer and halves (bins merge pairwise) whenever a delay would not fit.
  size_t coarseBinsPerOctave() const;
  /// Frames an entry is read out: seed = after its creation; EMA = after its last hit;
  /// window = the window length W.
  uint32_t lifetimeFrames() const;
  /// EMA coefficient a = 1 - exp(-T / tau) (1 when tau = 0, and for the other weightings).
  double emaCoefficient() const;
  /// Path entries merged into the coarse store since construction (none lost).
  uint64_t mergedEntries() const;
  /// Fraction of the last frame's response energy (band average) read out from the coarse
  /// store, in [0, 1].
  double coarseEnergyFraction() const;
  /// The oldest frame (counted from the start or the last clear) a path entry's age counts
  /// from: its creation (seed) or last hit (EMA, window); the frame count when there is none.
  uint32_t oldestEntryFrame() const;

 private:
  std::unique_ptr<PathCacheStore> store_;
};

}  // namespace dpc
