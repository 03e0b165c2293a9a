// The diffuse path cache's three weightings (engine/path_cache.h, docs/estimators.md), one type
// each over PathCacheStore (engine/path_cache_store.h), chosen once when the cache is built
// (makeWeightedStore): no per-hit or per-entry code asks which weighting runs. Each keeps its
// own entry type, whose fields say what they hold under that weighting:
// - SeedCache (kSeed, the thesis, section 3.2.2): sums since the entry's creation, read out as
//   I_hat / mu at r_hat / eta (eq. 3.2-3.4), removed after tau; coarse layers per creation frame.
// - EmaCache (kEma): exponential moving averages of the per-frame estimate I_f / N, decayed
//   every frame, normalised for start-up, dropped below kEmaDropFraction; one coarse layer.
// - WindowCache (kWindow): sums over the last W frames, each frame's terms kept in a ring and
//   subtracted when they leave the window; coarse layers per frame of the window.
// Internal to the engine. Threads, allocation and errors: as PathCacheStore.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <vector>

#include "common/bands.h"
#include "engine/cache_pool.h"
#include "engine/path_cache_store.h"
#include "scene/scene.h"

namespace dpc {

/// A seed entry: sums over the path's hits since the frame that created it (mu, the rays
/// emitted since then, is not stored: PathCacheStore::raysSince).
struct SeedEntry {
  uint64_t key = 0;  ///< path identifier
  uint32_t created = 0;  ///< frame that created the entry
  float hits = 0.f;  ///< eta: rays of this path that reached the listener (exact to 2^24)
  Bands intensitySum{0.f};  ///< I_hat: summed I, 1/m^2
  float lengthSum = 0.f;    ///< r_hat: summed r, metres
  glm::vec3 directionSum{0.f};  ///< summed arrival directions, weighted by mean band intensity
  uint32_t ageFrame() const { return created; }
};

/// An EMA entry: exponential moving averages (coefficient a) of the path's per-frame figures.
struct EmaEntry {
  uint64_t key = 0;  ///< path identifier
  uint32_t lastHit = 0;  ///< frame of the last hit
  float meanHits = 0.f;  ///< moving average of eta_f, hits per frame
  Bands meanEstimate{0.f};  ///< moving average of I_f / N, 1/m^2
  float meanLength = 0.f;   ///< moving average of r_f (the frame's summed lengths), metres
  glm::vec3 meanDirection{0.f};  ///< moving average of the frame's summed weighted directions
  uint32_t ageFrame() const { return lastHit; }
};

/// A window entry: sums of the path's per-frame figures over the frames of the window.
struct WindowEntry {
  uint64_t key = 0;  ///< path identifier
  uint32_t lastHit = 0;  ///< frame of the last hit (kMergedFrame: being merged)
  float hits = 0.f;  ///< eta: hits in the window
  Bands estimateSum{0.f};  ///< summed I_f / N, 1/m^2
  float lengthSum = 0.f;   ///< summed r, metres
  glm::vec3 directionSum{0.f};  ///< summed arrival directions, weighted by mean band intensity
  uint32_t ageFrame() const { return lastHit; }
};

/// One frame's contribution to one window entry.
struct WindowTerm {
  uint64_t key;
  Bands estimate;  ///< I_f / N, 1/m^2
  float length;    ///< r_f summed, metres
  float hits;      ///< hits this frame
  glm::vec3 direction;
};

static_assert(sizeof(SeedEntry) == kPathEntryBytes && sizeof(EmaEntry) == kPathEntryBytes &&
              sizeof(WindowEntry) == kPathEntryBytes);

class SeedCache final : public PathCacheStore {
 public:
  SeedCache(double tauSeconds, double framePeriodSeconds, size_t budgetBytes, CachePool* pool);
  size_t entryCount() const override { return table_.size(); }
  uint32_t oldestEntryFrame() const override;

 private:
  /// Adds the frame's groups (eq. 3.4) and reads every entry and layer out (eq. 3.2, 3.3).
  void applyFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                  ArrivalSink* directional, double& total, double& coarse) override;
  /// Merges the oldest entries into the layer of their creation frame: mu and the lifetime are
  /// shared, so I_hat / mu stays exactly additive.
  void makeRoom(double invC) override;
  void resizeTables() override;
  void clearEntries() override;
  /// Removes entries and the coarse layer that are tau old.
  void expire();

  PathTable<SeedEntry> table_;
  std::vector<uint32_t> layerCreated_;  ///< creation frame of each coarse layer
};

class EmaCache final : public PathCacheStore {
 public:
  EmaCache(double tauSeconds, double framePeriodSeconds, size_t budgetBytes, CachePool* pool);
  size_t entryCount() const override { return table_.size(); }
  uint32_t oldestEntryFrame() const override;

 private:
  /// Decays entries and coarse cells, adds the frame's groups, reads out normalised.
  void applyFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                  ArrivalSink* directional, double& total, double& coarse) override;
  /// Merges the oldest entries into the one coarse layer (a cell expires with its newest member).
  void makeRoom(double invC) override;
  void resizeTables() override;
  void clearEntries() override;
  /// Removes entries and coarse cells not hit for the lifetime.
  void expire();

  PathTable<EmaEntry> table_;
  double decayPow_ = 1.0;  ///< (1-a)^(frames + 1), for the start-up normalisation
};

class WindowCache final : public PathCacheStore {
 public:
  WindowCache(double tauSeconds, double framePeriodSeconds, size_t budgetBytes, CachePool* pool);
  size_t entryCount() const override { return table_.size(); }
  uint32_t oldestEntryFrame() const override;

 private:
  /// Retires the frame leaving the window, adds the frame's groups and terms, reads out the
  /// mean over the window's frames so far.
  void applyFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                  ArrivalSink* directional, double& total, double& coarse) override;
  /// Marks the oldest entries, moves their terms into the coarse rows of their frames and
  /// removes them, until a term is free.
  void makeRoom(double invC) override;
  void resizeTables() override;
  void clearEntries() override;
  size_t unusedTermBytes() const override;
  /// Reads every entry and the coarse rows' sums out as their mean over `frames` frames.
  void readOut(float frames, double invC, EnergyResponse& out, ArrivalSink* directional,
               double& total, double& coarse) const;
  /// Moves the terms of marked entries into the coarse rows of their frames, compacts the
  /// others and removes the marked entries.
  void mergeMarkedTerms(double invC);
  /// Takes the oldest frame's terms (ring slot `slot`) out of their entries.
  void retireSlot(size_t slot);
  size_t slotOf(uint64_t frame) const { return size_t(frame % shape_.lifetime); }

  /// Makes a full ring longer, up to the terms' capacity.
  void widenRing();

  /// Terms the ring widens by at least (64 kB): its length follows the terms held, so the
  /// pages a wrapping ring writes are about those the window needs, not the whole capacity
  /// (which is sized for two terms per entry; many rooms need nearer one).
  static constexpr size_t kRingStep = 1024;

  PathTable<WindowEntry> table_;
  Buffer<WindowTerm> terms_;  ///< FIFO ring of the window's path terms, in [0, ringSize_)
  size_t termHead_ = 0, termCount_ = 0;
  size_t ringSize_ = 0;  ///< the ring's length, <= cap_.windowTerms
  std::vector<uint32_t> slotTerms_;  ///< path terms per frame slot
};

/// The store of `weighting` (the one place the weighting is chosen). Throws as
/// PathCacheLimits::capacityFor. Allocates.
std::unique_ptr<PathCacheStore> makeWeightedStore(DpcWeighting weighting, double tauSeconds,
                                                  double framePeriodSeconds, size_t budgetBytes,
                                                  CachePool* pool);

}  // namespace dpc
