// Estimators that turn one frame's listener hits into an energy response: plain Monte Carlo
// path tracing and the diffuse path cache (DPC) of Schissler's thesis, section 3.2.2.
//
// Both see the frame's hits grouped by path identifier (FrameGroups, in first-hit order).
// - PathTracingEstimator: every group adds I_f / N at delay (r_f / eta_f) / c, nothing is
//   kept between frames.
// - DiffusePathCache: entries (eta, mu, I_hat, r_hat, created) persist across frames.
//   Weighting kSeed is the thesis: eq. 3.4 update, eq. 3.2 I_bar = I_hat / mu, eq. 3.3
//   r_bar = r_hat / eta, removal after tau. Weighting kEma is dpc's unbiased variant: each
//   entry keeps an exponential moving average (time constant tau) of its per-frame estimate
//   I_f / N, decayed every frame whether hit or not, normalised by 1 - (1-a)^(n+1) for the
//   n+1 frames since the cache started, and dropped once its weight falls below
//   kEmaDropFraction (docs/estimators.md has the derivation and the measurements).
//   Weighting kWindow: each entry holds the sums of its per-frame estimates over the last
//   W = round(tau / T) frames (at least 1) and reads out their mean, sum / min(frames so far,
//   W); each frame's contributions are kept in a ring of W frames and subtracted when they
//   leave the window; an entry with no hit left in the window is removed. Unbiased for a
//   static scene, and a step is answered completely W frames later.
// With tau = 0 every weighting reduce to PathTracingEstimator, bit for bit (the same float
// operations in the same order); tests/engine/path_cache_test.cpp checks it.
// Propagation thread only. Allocation: FrameGroups grows as needed, then keeps its capacity;
// DiffusePathCache starts with tables of kInitialTableBytes and doubles them while its paths
// need room, up to its budget and as far as its CachePool (engine/cache_pool.h) gives the bytes;
// only then does it merge entries into its coarse store.
#pragma once

#include <tsl/robin_map.h>

#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "common/bands.h"
#include "engine/cache_pool.h"
#include "engine/energy_response.h"
#include "scene/scene.h"

namespace dpc {

/// One ray segment that crossed the listener sphere.
struct PathHit {
  uint64_t key = 0;          ///< path identifier hash K (engine/patch.h)
  Bands intensity{0.f};      ///< I(omega) = band energy * air attenuation / (pi R^2), 1/m^2
  float length = 0.f;        ///< r, path length to the listener, metres
  glm::vec3 direction{0.f};  ///< unit vector from the listener toward the arriving sound
};

/// A frame's hits grouped by path identifier, in order of each key's first hit.
class FrameGroups {
 public:
  struct Group {
    uint64_t key;
    uint32_t eta;         ///< hits this frame
    Bands intensity;      ///< summed I, 1/m^2
    float length;         ///< summed r, metres
    glm::vec3 direction;  ///< summed direction weighted by mean band intensity
  };
  void clear();
  void add(const PathHit& hit);
  const std::vector<Group>& groups() const { return groups_; }
  size_t hitCount() const { return hits_; }

 private:
  tsl::robin_map<uint64_t, uint32_t> index_;
  std::vector<Group> groups_;
  size_t hits_ = 0;
};

/// Plain Monte Carlo path tracing: no memory between frames.
/// Delay in seconds of a group or entry: (summed length / count) / c. The one expression both
/// estimators use, so that tau = 0 gives bit-identical responses.
inline double meanDelaySeconds(float lengthSum, float count, double invSpeedOfSound) {
  return double(lengthSum) / double(count) * invSpeedOfSound;
}

class PathTracingEstimator {
 public:
  /// Adds every group's I_f / N at delay (r_f / eta_f) / c to out. N = rays emitted this frame.
  /// directional (optional): also receives every contribution with its arrival direction.
  void endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                EnergyResponse& out, ArrivalSink* directional = nullptr) const;
};

class DiffusePathCache {
 public:
  /// Weight below which an EMA entry that is no longer hit is dropped (bias <= this fraction
  /// of one hit's contribution).
  static constexpr double kEmaDropFraction = 1e-3;
  /// Default memory budget per cache (one cache per source-listener pair), megabytes.
  static constexpr double kDefaultBudgetMb = 64.0;
  /// Default budget in bytes (kDefaultBudgetMb MiB).
  static constexpr size_t kDefaultBudgetBytes = size_t(kDefaultBudgetMb * 1048576.0);
  /// Finest coarse-store delay bin, seconds (the energy response's own bin width).
  static constexpr double kCoarseBinSeconds = 1e-3;
  /// Most coarse-store delay bins; the bin width doubles when a delay does not fit.
  static constexpr size_t kMaxCoarseBins = 4096;
  /// Bytes of a cache's first path tables (entries, index, window terms): a few thousand paths,
  /// grown by doubling as they fill.
  static constexpr size_t kInitialTableBytes = size_t(1) << 18;
  /// The most bytes of a cache's coarse store (with its fixed tables): a quarter of this goes
  /// to coarse cells, whatever the budget, so that many pairs' stores stay small; its delay
  /// bins widen (log-spaced) when a merged delay does not fit.
  static constexpr size_t kCoarseBudgetBytes = size_t(2) << 20;

  /// How a budget is split (all tables are allocated once, at construction, to these sizes).
  struct Capacity {
    size_t entries = 0;      ///< path entries (64 bytes each)
    size_t indexSlots = 0;   ///< open-addressing index slots (16 bytes each, load <= 3/4)
    size_t windowTerms = 0;  ///< kWindow: per-frame terms of path entries (64 bytes each)
    size_t coarseBins = 0;   ///< coarse-store delay bins (per layer: seed L, window W, EMA 1)
    size_t bytes = 0;        ///< everything the cache allocates, <= the budget
  };
  /// The split of budgetBytes for a weighting, tau and frame period: a quarter of the budget, at
  /// most of kCoarseBudgetBytes, for the coarse store (at most kMaxCoarseBins bins per layer),
  /// the rest for path entries, their
  /// index and (window) their per-frame terms, two per entry. Throws std::invalid_argument
  /// when the budget cannot hold one path entry and one coarse bin, saying the budget these
  /// settings need ("cache_memory_mb: ...") or that tau keeps too many frames for any budget
  /// ("cache_tau: ...").
  static Capacity capacityFor(DpcWeighting weighting, double tauSeconds, double framePeriodSeconds,
                              size_t budgetBytes);

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
  /// arguments (see capacityFor).
  DiffusePathCache(DpcWeighting weighting, double tauSeconds, double framePeriodSeconds,
                   size_t budgetBytes = kDefaultBudgetBytes, CachePool* pool = nullptr);
  ~DiffusePathCache();
  DiffusePathCache(const DiffusePathCache&) = delete;
  DiffusePathCache& operator=(const DiffusePathCache&) = delete;

  /// One frame: applies the frame's groups (eq. 3.4, the EMA or the window), reads out every
  /// entry and coarse cell into out, then removes expired entries. directional (optional):
  /// also receives every estimate with its mean arrival direction (intensity-weighted over
  /// the entry's hits). Does not allocate.
  void endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                EnergyResponse& out, ArrivalSink* directional = nullptr);

  void clear();
  /// Path entries (coarse cells not included).
  size_t entryCount() const { return entries_.size(); }
  /// Non-empty coarse-store cells (delay bins per layer holding merged energy).
  size_t coarseEntryCount() const;
  /// Most path entries the current tables hold (the budget's at most).
  size_t maxEntries() const { return cap_.entries; }
  /// The budget, bytes.
  size_t budgetBytes() const { return budget_; }
  /// Heap bytes held by the cache's tables now (they grow as paths need room), <= budgetBytes().
  size_t bytes() const { return cap_.bytes; }
  /// Table growths the pool refused (the cache merged instead), since construction.
  uint64_t refusedGrowths() const { return refused_; }
  /// Heap bytes of the slots in use (entries, index load, window terms, coarse cells).
  size_t bytesInUse() const;
  /// Coarse-store layout: delays below S ms in 1 ms bins, then S bins per octave (each octave
  /// [S 2^k, S 2^(k+1)) ms in bins of 2^k ms). S starts at the largest power of two <= the
  /// bins per layer and halves (bins merge pairwise) whenever a delay would not fit.
  size_t coarseBinsPerOctave() const { return coarseSub_; }
  /// Frames an entry is read out: seed = after its creation; EMA = after its last hit;
  /// window = the window length W.
  uint32_t lifetimeFrames() const { return lifetime_; }
  /// EMA coefficient a = 1 - exp(-T / tau) (1 when tau = 0).
  double emaCoefficient() const { return a_; }

  /// 64 bytes. mu (rays emitted while the entry existed) is not stored: it is the rays
  /// emitted since the entry's creation frame, kept per frame in a small ring.
  struct Entry {
    uint64_t key;
    uint32_t stamp;       ///< seed: frame created; EMA and window: frame last hit
    float eta;            ///< seed: rays of this path that reached the listener (exact to 2^24);
                          ///< EMA: moving average of eta_f; window: hits in the window
    Bands intensity;      ///< seed: I_hat (sum); EMA: moving average of I_f / N; window: sum
    float length;         ///< seed: r_hat (sum); EMA: moving average of r_f; window: sum
    glm::vec3 direction;  ///< summed / averaged arrival direction (intensity weighted)
  };
  static_assert(sizeof(Entry) == 64);
  /// Path entries merged into the coarse store since construction (none lost).
  uint64_t mergedEntries() const { return merged_; }
  /// Fraction of the last frame's response energy (band average) read out from the coarse
  /// store, in [0, 1].
  double coarseEnergyFraction() const { return coarseFraction_; }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  /// capacityFor's split, or nothing where capacityFor throws.
  static std::optional<Capacity> splitBudget(DpcWeighting weighting, double tauSeconds,
                                             double framePeriodSeconds, size_t budgetBytes);
  /// kWindow: one frame's contribution to one path entry.
  struct WindowTerm {
    uint64_t key;
    Bands intensity;  ///< I_f / N
    float length;     ///< r_f summed
    float eta;        ///< hits this frame
    glm::vec3 direction;
  };
  /// A coarse-store cell: summed state of the path entries merged into it.
  struct Cell {
    Bands intensity;
    float length;
    float eta;
    glm::vec3 direction;
    uint32_t stamp;  ///< EMA: newest member's last hit
  };
  struct IndexSlot {
    uint64_t key;
    uint32_t index1;  ///< entry index + 1; 0 = empty
  };
  struct FreeDeleter {
    void operator()(void* p) const;
  };
  template <class T>
  using Buffer = std::unique_ptr<T[], FreeDeleter>;

  size_t indexFind(uint64_t key) const;  ///< slot of key, or indexSlots when absent
  void indexInsert(uint64_t key, uint32_t index);
  void indexErase(uint64_t key);
  uint32_t indexOf(uint64_t key) const;  ///< entry index of a present key

  Entry* findOrInsert(uint64_t key, bool& inserted);
  /// Doubles the path tables (entries, index, window terms) within the budget when the pool
  /// gives the bytes; false when they cannot grow.
  bool grow();
  /// The path tables' capacity for `tableBudget` bytes, with the coarse store of cap_.
  Capacity tablesFor(size_t tableBudget) const;
  /// Bytes of the whole budget's coarse store and fixed tables (maxCap_ without path tables).
  size_t coarseBytes() const;
  void removeAt(size_t i);
  /// Makes room for at least one more path entry and (window) one more term: merges the
  /// oldest path entries, at least an eighth of the table, into the coarse store.
  void makeRoom(double invSpeedOfSound);
  /// kWindow part of makeRoom: moves the terms of entries stamped for merging into the coarse
  /// rows of their frames, compacts the others and removes the merged entries.
  void mergeMarkedTerms(double invC);
  /// Coarse bin of a delay at the current layout, halving S until it fits.
  size_t coarseBin(double delaySeconds);
  /// Bin of a delay of `fine` whole kCoarseBinSeconds steps with S bins per octave.
  static size_t binOf(uint64_t fine, size_t sub);
  /// First kCoarseBinSeconds step of a bin with S bins per octave (inverse of binOf).
  static uint64_t binStart(size_t bin, size_t sub) {
    if (bin < sub) return bin;
    const size_t k = bin / sub - 1;
    return uint64_t(bin - sub * k) << k;
  }
  void widenCoarse();
  Cell& cell(size_t layer, size_t bin) { return coarse_[layer * cap_.coarseBins + bin]; }
  void readCell(const Cell& c, size_t bin, float divisor, double invC, EnergyResponse& out,
                ArrivalSink* directional, double& energy) const;
  void windowEndFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                      ArrivalSink* directional, double& total, double& coarse);
  size_t windowSlot(uint64_t frame) const { return size_t(frame % lifetime_); }
  /// kWindow: takes the oldest frame's terms (ring slot `slot`) out of their entries.
  void retireWindowSlot(size_t slot);
  /// Reads every path entry out with its intensity divided by `divisor`; adds the band-average
  /// energy to total.
  void readEntries(float divisor, double invC, EnergyResponse& out, ArrivalSink* directional,
                   double& total) const;
  /// kSeed: adds the frame's groups (eq. 3.4) and reads every entry and layer out (eq. 3.2,
  /// 3.3); total and coarse add the band-average energy read out (all, coarse store).
  void seedEndFrame(const FrameGroups& frame, double invC, EnergyResponse& out,
                    ArrivalSink* directional, double& total, double& coarse);
  /// kEma: decays entries and coarse cells, adds the frame's groups, reads out normalised.
  void emaEndFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                   ArrivalSink* directional, double& total, double& coarse);
  /// Merges the oldest entries into the coarse store if `key` is new and the table is full.
  void makeRoomFor(uint64_t key, double invC);
  /// kSeed, kEma: removes entries and coarse cells older than the lifetime.
  void expire();

  DpcWeighting weighting_;
  double a_ = 1.0;
  uint32_t lifetime_ = 1;
  size_t layers_ = 1;      ///< coarse layers: seed L (creation frames), window W (frames), EMA 1
  uint32_t frame_ = 0;     ///< frames since the cache started (or was cleared)
  double decayPow_ = 1.0;  ///< (1-a)^(frame_+1), for the start-up normalisation
  size_t budget_;
  Capacity cap_;     ///< the current tables (coarse bins: the whole budget's)
  Capacity maxCap_;  ///< the whole budget's tables
  double tau_ = 0.0, period_ = 1.0;
  CachePool* pool_ = nullptr;
  size_t reserved_ = 0;  ///< bytes taken from pool_
  uint64_t refused_ = 0;
  uint64_t merged_ = 0;
  double coarseFraction_ = 0.0;
  uint64_t raysTotal_ = 0;            ///< rays emitted since the start, this frame included
  std::vector<uint64_t> raysBefore_;  ///< ring: rays emitted before frame f, f % size
  std::vector<uint32_t> ageCount_;    ///< scratch for makeRoom: entries per age in frames
  std::vector<uint32_t> layerStamp_;  ///< seed: creation frame of each coarse layer
  /// Per coarse layer: may hold a cell with eta > 0 (set on every merge into it, cleared when
  /// the layer is emptied). Readouts and counts skip the others: without merges (a budget
  /// large enough for the scene) the coarse store costs nothing per frame.
  std::vector<uint8_t> layerUsed_;
  size_t coarseSub_ = 1;        ///< S: coarse bins per octave (see coarseBinsPerOctave)
  Buffer<Cell> coarse_;         ///< layers_ x coarseBins cells
  Buffer<IndexSlot> index_;     ///< open addressing, linear probing
  int indexShift_ = 63;         ///< 64 - log2(indexSlots)
  std::vector<Entry> entries_;  ///< reserved to cap_.entries once
  Buffer<WindowTerm> terms_;    ///< kWindow: FIFO ring of the window's path terms
  size_t termHead_ = 0, termCount_ = 0;
  std::vector<uint32_t> slotTerms_;  ///< kWindow: path terms per frame slot
};

}  // namespace dpc
