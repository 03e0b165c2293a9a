// PathCacheStore: what the diffuse path cache (engine/path_cache.h) holds whatever its
// weighting, and the one interface DiffusePathCache drives a weighting through. It owns the
// budget and its split (PathCacheLimits::Capacity), the growth of the path tables from the
// cache pool, the rays-emitted ring, and the coarse store that the oldest paths are merged into
// when the tables are full: layers x delay bins of CoarseCell (1 ms bins, then log-spaced,
// widened when a delay does not fit), read out linearly. A weighting (engine/
// path_cache_weightings.h) derives from it, keeps its own entry type in a PathTable and
// implements the frame (applyFrame), the merge of its oldest entries (makeRoom) and its
// tables' growth. Internal to the engine.
//
// Threads: the propagation thread that runs the cache's frames. Allocation: at construction,
// and when the path tables grow (grow()); none otherwise. Errors: the constructor throws
// std::invalid_argument as PathCacheLimits::capacityFor, std::bad_alloc when out of memory.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <glm/vec3.hpp>
#include <memory>
#include <new>
#include <optional>
#include <vector>

#include "common/bands.h"
#include "engine/cache_pool.h"
#include "engine/energy_response.h"
#include "engine/frame_groups.h"
#include "scene/scene.h"

namespace dpc {

/// Bytes of one path entry of every weighting (engine/path_cache_weightings.h).
inline constexpr size_t kPathEntryBytes = 64;

/// The diffuse path cache's fixed sizes and how a budget is split among its tables
/// (DiffusePathCache, engine/path_cache.h, derives from it).
struct PathCacheLimits {
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
  /// the rest for path entries, their index and (window) their per-frame terms, two per entry.
  /// Throws std::invalid_argument when the budget cannot hold one path entry and one coarse
  /// bin, saying the budget these settings need ("cache_memory_mb: ...") or that tau keeps too
  /// many frames for any budget ("cache_tau: ..."). Any thread; no allocation but the message.
  static Capacity capacityFor(DpcWeighting weighting, double tauSeconds, double framePeriodSeconds,
                              size_t budgetBytes);
};

/// How a weighting shapes its cache, fixed at construction.
struct WeightingShape {
  /// Frames an entry is read out: seed after its creation (round(tau / T), at least 1); EMA
  /// after its last hit (until its weight falls below PathCacheLimits::kEmaDropFraction); window W frames.
  uint32_t lifetime = 1;
  double emaCoefficient = 1.0;  ///< EMA: a = 1 - exp(-T / tau) (1 when tau = 0); others 1
  size_t coarseLayers = 1;      ///< seed: L (one per creation frame); window: W (frames); EMA: 1
  size_t termsPerEntry = 0;     ///< window: per-frame terms kept, 2 per entry; others 0
  size_t termBytes = 0;         ///< window: bytes of one per-frame term
};
/// The shape of `weighting` for tau and the frame period (seconds). Any thread; no errors.
WeightingShape weightingShape(DpcWeighting weighting, double tauSeconds, double framePeriodSeconds);
/// The split of budgetBytes for a shape (PathCacheLimits::capacityFor without the errors), or
/// nothing when the budget cannot hold one path entry and one coarse bin.
std::optional<PathCacheLimits::Capacity> splitBudget(const WeightingShape& shape,
                                                      size_t budgetBytes);

/// Memory from calloc (zeroed; the OS commits pages as they are written), freed with free.
struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};
template <class T>
using Buffer = std::unique_ptr<T[], FreeDeleter>;
/// n zeroed T (nullptr for n = 0). Throws std::bad_alloc.
template <class T>
Buffer<T> allocZeroed(size_t n) {
  if (n == 0) return nullptr;
  void* p = std::calloc(n, sizeof(T));
  if (!p) throw std::bad_alloc();
  return Buffer<T>(static_cast<T*>(p));
}

/// The path tables' index: path identifier -> entry index. Open addressing: Fibonacci hashing
/// of the key (test keys are small integers), linear probing, backward-shift deletion (no
/// tombstones, so probe lengths stay short at load 3/4).
class PathIndex {
 public:
  static constexpr size_t kSlotBytes = 16;
  /// An empty index of `slots` (a power of two) slots, its pages committed. Allocates.
  void reset(size_t slots);
  /// The slot of `key`, or slots() when absent.
  size_t find(uint64_t key) const;
  uint32_t entryAt(size_t slot) const { return slots_[slot].index1 - 1; }
  void setEntryAt(size_t slot, uint32_t index) { slots_[slot].index1 = index + 1; }
  void insert(uint64_t key, uint32_t index);
  void erase(uint64_t key);
  size_t slots() const { return count_; }

 private:
  struct Slot {
    uint64_t key;
    uint32_t index1;  ///< entry index + 1; 0 = empty
  };
  static_assert(sizeof(Slot) == kSlotBytes);
  size_t home(uint64_t key) const { return size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  Buffer<Slot> slots_;
  size_t count_ = 0;
  int shift_ = 63;  ///< 64 - log2(slots)
};

/// One weighting's path entries (Entry: engine/path_cache_weightings.h; a key, then the frame
/// its age counts from, then its state) with their index. Removal moves the last entry into the
/// hole, so entry order is insertion order but for removals.
template <class Entry>
class PathTable {
 public:
  std::vector<Entry>& entries() { return entries_; }
  const std::vector<Entry>& entries() const { return entries_; }
  size_t size() const { return entries_.size(); }
  bool contains(uint64_t key) const { return index_.find(key) != index_.slots(); }
  /// The entry index of a present key.
  uint32_t indexOf(uint64_t key) const { return index_.entryAt(index_.find(key)); }
  /// The entry of `key`, appended with a zero state stamped `frame` if absent (then inserted =
  /// true). The table must have room (capacity) for a new entry: no allocation.
  Entry* findOrInsert(uint64_t key, uint32_t frame, bool& inserted) {
    const size_t slot = index_.find(key);
    inserted = slot == index_.slots();
    if (!inserted) return &entries_[index_.entryAt(slot)];
    index_.insert(key, uint32_t(entries_.size()));
    entries_.push_back(Entry{key, frame});
    return &entries_.back();
  }
  void removeAt(size_t i) {
    index_.erase(entries_[i].key);
    if (i + 1 != entries_.size()) {
      entries_[i] = entries_.back();
      index_.setEntryAt(index_.find(entries_[i].key), uint32_t(i));
    }
    entries_.pop_back();
  }
  /// A new index of `slots` slots holding every entry, and room for `capacity` entries.
  /// Allocates.
  void resize(size_t slots, size_t capacity) {
    index_.reset(slots);
    for (size_t i = 0; i < entries_.size(); ++i) index_.insert(entries_[i].key, uint32_t(i));
    entries_.reserve(capacity);
  }
  void clear() {
    for (const Entry& e : entries_) index_.erase(e.key);
    entries_.clear();
  }

 private:
  PathIndex index_;
  std::vector<Entry> entries_;
};

/// A coarse-store cell: the sums of the states of the entries (window: of the per-frame terms)
/// merged into it, field by field in the weighting's own terms (engine/path_cache_weightings.h).
struct CoarseCell {
  Bands intensity;       ///< summed intensities or estimates, 1/m^2
  float length;          ///< summed lengths, metres
  float hits;            ///< summed hit counts (eta); > 0 when the cell holds anything
  glm::vec3 direction;   ///< summed intensity-weighted directions
  uint32_t lastHit;      ///< EMA: the newest member's last hit (when the cell expires)
};

class PathCacheStore {
 public:
  using Capacity = PathCacheLimits::Capacity;
  virtual ~PathCacheStore();
  PathCacheStore(const PathCacheStore&) = delete;
  PathCacheStore& operator=(const PathCacheStore&) = delete;

  /// One frame (DiffusePathCache::endFrame): counts the rays, lets the weighting apply and read
  /// out the frame, and keeps the coarse store's share of the energy.
  void endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                EnergyResponse& out, ArrivalSink* directional);
  /// DiffusePathCache::clear.
  void clear();

  virtual size_t entryCount() const = 0;
  virtual uint32_t oldestEntryFrame() const = 0;
  size_t coarseEntryCount() const;
  size_t bytesInUse() const;
  const Capacity& capacity() const { return cap_; }
  size_t budgetBytes() const { return budget_; }
  uint64_t refusedGrowths() const { return refused_; }
  /// Between frames, on the thread that runs them: the growth the pool refused during the
  /// last frame (its frame share was spent), tried again now, so that a cache that needs more
  /// than a share still grows as far as the pool allows, in an order the caller fixes.
  void growDeferred() {
    if (!growthDeferred_) return;
    growthDeferred_ = false;
    if (grow()) return;
    growthDeferred_ = false;  // the pool is full: the cache merges until a later growth fits
    ++refused_;
  }
  uint64_t mergedEntries() const { return merged_; }
  double coarseEnergyFraction() const { return coarseFraction_; }
  size_t coarseBinsPerOctave() const { return coarseSub_; }
  const WeightingShape& shape() const { return shape_; }

 protected:
  /// Splits the budget (PathCacheLimits::capacityFor for `weighting`; throws as it does),
  /// allocates the coarse store for the whole budget and reserves the first tables' bytes from
  /// the pool. The derived weighting allocates its tables to capacity().
  PathCacheStore(DpcWeighting weighting, double tauSeconds, double framePeriodSeconds,
                 size_t budgetBytes, CachePool* pool);

  /// The weighting's frame: applies the groups, reads every entry and coarse cell out into out
  /// (and directional), adds the band-average energy read out to total and, of it, the coarse
  /// store's to coarse, then removes what expired. n: rays emitted this frame.
  virtual void applyFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                          ArrivalSink* directional, double& total, double& coarse) = 0;
  /// Makes room for at least one more path entry (and window term): merges the oldest path
  /// entries, at least an eighth of the table, into the coarse store.
  virtual void makeRoom(double invC) = 0;
  /// The weighting's tables anew for capacity() after a growth, their entries kept.
  virtual void resizeTables() = 0;
  /// Empties the weighting's entries and state (DiffusePathCache::clear).
  virtual void clearEntries() = 0;
  /// Bytes of the weighting's allocated but unused per-frame terms (bytesInUse).
  virtual size_t unusedTermBytes() const { return 0; }

  /// Doubles the path tables within the budget when the pool gives the bytes; false when they
  /// cannot grow.
  bool grow();
  /// Merges the oldest entries if `key` is new and the table is full and cannot grow.
  template <class Entry>
  void makeRoomFor(const PathTable<Entry>& table, uint64_t key, double invC) {
    if (table.size() == cap_.entries && !table.contains(key) && !grow()) makeRoom(invC);
  }
  /// Which entries makeRoom merges: every entry older than `age` frames, and of those exactly
  /// `age` old the first `quota` met walking the table from its end.
  struct OldestCut {
    size_t age = 0;
    size_t quota = 0;
    /// Whether the entry of `age` frames is merged (walking from the end; counts the quota).
    bool takes(size_t entryAge) {
      if (entryAge < age || (entryAge == age && quota == 0)) return false;
      if (entryAge == age) --quota;
      return true;
    }
  };
  /// Frames since `frame` (capped at the lifetime).
  size_t ageOf(uint32_t frame) const { return std::min<size_t>(frame_ - frame, shape_.lifetime); }
  /// The cut that merges the oldest eighth of the table (at least one entry), by ageFrame().
  template <class Entry>
  OldestCut oldestCut(const std::vector<Entry>& entries) {
    const size_t target = std::max<size_t>(1, cap_.entries / 8);
    std::fill(ageCount_.begin(), ageCount_.end(), 0);
    for (const Entry& e : entries) ++ageCount_[ageOf(e.ageFrame())];
    size_t age = ageCount_.size(), count = 0;
    while (age > 0 && count < target) count += ageCount_[--age];
    return {age, ageCount_[age] - (count - std::min(count, target))};
  }
  /// Rays emitted from the start of `frame` through this one (seed's mu).
  float raysSince(uint32_t frame) const {
    return float(raysTotal_ - raysBefore_[frame % raysBefore_.size()]);
  }

  /// Coarse bin of a delay at the current layout, halving S until it fits.
  size_t coarseBin(double delaySeconds);
  CoarseCell& cell(size_t layer, size_t bin) { return coarse_[layer * cap_.coarseBins + bin]; }
  const CoarseCell& coarseCell(size_t layer, size_t bin) const {
    return coarse_[layer * cap_.coarseBins + bin];
  }
  /// Empties a coarse layer.
  void clearLayer(size_t layer);
  /// Reads a coarse cell of bin `bin` out with its intensity divided by `divisor` (at its mean
  /// delay, or spread over a wide bin); adds the band-average energy to `energy`.
  void readCell(const CoarseCell& c, size_t bin, float divisor, double invC, EnergyResponse& out,
                ArrivalSink* directional, double& energy) const;

  WeightingShape shape_;
  uint32_t frame_ = 0;  ///< frames since the cache started (or was cleared)
  Capacity cap_;        ///< the current tables (coarse bins: the whole budget's)
  uint64_t merged_ = 0;
  /// Per coarse layer: may hold a cell with hits > 0 (set on every merge into it, cleared when
  /// the layer is emptied). Readouts and counts skip the others: without merges (a budget
  /// large enough for the scene) the coarse store costs nothing per frame.
  std::vector<uint8_t> layerUsed_;

 private:
  /// The path tables' capacity for `tableBudget` bytes, with the coarse store of cap_.
  Capacity tablesFor(size_t tableBudget) const;
  /// Bytes of the whole budget's coarse store and fixed tables (maxCap_ without path tables).
  size_t coarseBytes() const;
  /// Bin of a delay of `fine` whole kCoarseBinSeconds steps with S bins per octave.
  static size_t binOf(uint64_t fine, size_t sub);
  /// First kCoarseBinSeconds step of a bin with S bins per octave (inverse of binOf).
  static uint64_t binStart(size_t bin, size_t sub) {
    if (bin < sub) return bin;
    const size_t k = bin / sub - 1;
    return uint64_t(bin - sub * k) << k;
  }
  void widenCoarse();

  size_t budget_;
  Capacity maxCap_;  ///< the whole budget's tables
  CachePool* pool_ = nullptr;
  size_t reserved_ = 0;  ///< bytes taken from pool_
  CachePool::FrameTake frameTake_;  ///< this frame's takes from pool_
  bool growthDeferred_ = false;      ///< a growth refused in the frame, to retry after it
  uint64_t refused_ = 0;
  double coarseFraction_ = 0.0;
  uint64_t raysTotal_ = 0;            ///< rays emitted since the start, this frame included
  std::vector<uint64_t> raysBefore_;  ///< ring: rays emitted before frame f, f % size
  std::vector<uint32_t> ageCount_;    ///< scratch for oldestCut: entries per age in frames
  size_t coarseSub_ = 1;              ///< S: coarse bins per octave (see coarseBinsPerOctave)
  Buffer<CoarseCell> coarse_;         ///< shape_.coarseLayers x coarseBins cells
};

}  // namespace dpc
