// The diffuse path cache's tables: each weighting's shape, how a budget is split (capacityFor),
// the tables' allocation at construction and their growth from the cache pool (grow). The
// weightings themselves are engine/path_cache_weightings.cpp, the coarse store's merges and
// readout engine/path_cache_store.cpp.
#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "engine/path_cache_store.h"
#include "engine/path_cache_weightings.h"

namespace dpc {

namespace {

/// Writes one byte per 4 KiB of p[0, bytes) so the pages are committed now. The index is hashed,
/// so a table in use touches all its pages within a few frames anyway; committing them at
/// construction keeps those first frames free of page faults (each a read fault mapping the
/// shared zero page, then a copy-on-write fault whose TLB flush interrupts every core).
void commitPages(void* p, size_t bytes) {
  volatile unsigned char* c = static_cast<unsigned char*>(p);
  for (size_t i = 0; i < bytes; i += 4096) c[i] = 0;
}

}  // namespace

WeightingShape weightingShape(DpcWeighting weighting, double tau, double period) {
  WeightingShape s;
  if (weighting == DpcWeighting::kEma) {
    s.emaCoefficient = tau > 0.0 ? 1.0 - std::exp(-period / tau) : 1.0;
    // Read out at the frame of the last hit and M more frames, (1-a)^M <= drop fraction.
    const double a = s.emaCoefficient;
    s.lifetime = a >= 1.0 ? 1u
                          : 1u + uint32_t(std::ceil(std::log(PathCacheLimits::kEmaDropFraction) /
                                                    std::log(1.0 - a)));
    return s;  // one coarse layer
  }
  // Seed: read out in the creation frame and until tau old; window: W = round(tau / T) frames.
  s.lifetime = uint32_t(std::max(1.0, std::round(tau / period)));
  s.coarseLayers = s.lifetime;
  if (weighting == DpcWeighting::kWindow) {
    s.termsPerEntry = 2;
    s.termBytes = sizeof(WindowTerm);
  }
  return s;
}

std::optional<PathCacheLimits::Capacity> splitBudget(const WeightingShape& shape,
                                                      size_t budgetBytes) {
  using Cache = PathCacheLimits;
  const size_t lifetime = shape.lifetime;
  const size_t layers = shape.coarseLayers;
  const bool window = shape.termsPerEntry > 0;
  // Fixed tables: the rays ring, the age histogram, seed layer stamps, window slot counts.
  const size_t fixed = (lifetime + 1) * sizeof(uint64_t) + (lifetime + 1) * sizeof(uint32_t) +
                       layers * sizeof(uint32_t) + (window ? lifetime * sizeof(uint32_t) : 0);
  Cache::Capacity c;
  const size_t perBin = layers * sizeof(CoarseCell);
  c.coarseBins = std::min(Cache::kMaxCoarseBins,
                          std::min(budgetBytes, Cache::kCoarseBudgetBytes) / 4 / perBin);
  const size_t perEntry = kPathEntryBytes + shape.termsPerEntry * shape.termBytes;
  const size_t used = fixed + c.coarseBins * perBin;
  if (c.coarseBins == 0 || used >= budgetBytes) return std::nullopt;
  const size_t rest = budgetBytes - used;
  // Index slots a power of two at load <= 3/4: pick the size that holds the most entries.
  for (size_t slots = 2; slots * PathIndex::kSlotBytes < rest; slots *= 2) {
    const size_t e = std::min(slots / 4 * 3, (rest - slots * PathIndex::kSlotBytes) / perEntry);
    if (e > c.entries) c.entries = e, c.indexSlots = slots;
  }
  if (c.entries == 0) return std::nullopt;
  c.windowTerms = shape.termsPerEntry * c.entries;
  c.bytes = used + c.entries * kPathEntryBytes + c.indexSlots * PathIndex::kSlotBytes +
            c.windowTerms * shape.termBytes;
  return c;
}

PathCacheLimits::Capacity PathCacheLimits::capacityFor(DpcWeighting weighting, double tauSeconds,
                                                       double framePeriodSeconds,
                                                       size_t budgetBytes) {
  if (!(tauSeconds >= 0.0) || !(framePeriodSeconds > 0.0))
    throw std::invalid_argument("DiffusePathCache: tau must be >= 0 and frame period > 0");
  const WeightingShape shape = weightingShape(weighting, tauSeconds, framePeriodSeconds);
  if (auto c = splitBudget(shape, budgetBytes)) return *c;
  // The smallest budget that holds one path entry and one coarse bin (a larger budget gives
  // every table at least as much): beyond 2^40 bytes, the frames tau keeps are too many.
  size_t lo = budgetBytes, hi = size_t(1) << 40;
  if (!splitBudget(shape, hi)) {
    throw std::invalid_argument(
        "cache_tau: " + std::to_string(shape.lifetime) +
        " frames of paths (cache_tau x frame_rate) are more than the path cache's coarse store "
        "holds (" +
        std::to_string(kCoarseBudgetBytes / 4 / sizeof(CoarseCell)) +
        "): lower cache_tau or frame_rate");
  }
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    (splitBudget(shape, mid) ? hi : lo) = mid;
  }
  throw std::invalid_argument("cache_memory_mb: a budget of " + std::to_string(budgetBytes) +
                              " bytes per source-listener pair is below the " + std::to_string(hi) +
                              " this cache_tau and frame_rate need (MB = 1048576 bytes)");
}

void PathIndex::reset(size_t slots) {
  slots_ = allocZeroed<Slot>(slots);
  commitPages(slots_.get(), slots * sizeof(Slot));
  count_ = slots;
  shift_ = 64 - int(std::countr_zero(slots));
}

PathCacheStore::PathCacheStore(DpcWeighting weighting, double tauSeconds,
                               double framePeriodSeconds, size_t budgetBytes, CachePool* pool)
    : shape_(weightingShape(weighting, tauSeconds, framePeriodSeconds)),
      budget_(budgetBytes),
      pool_(pool) {
  maxCap_ = PathCacheLimits::capacityFor(weighting, tauSeconds, framePeriodSeconds, budgetBytes);
  cap_ = tablesFor(PathCacheLimits::kInitialTableBytes);
  raysBefore_.assign(size_t(shape_.lifetime) + 1, 0);
  ageCount_.assign(size_t(shape_.lifetime) + 1, 0);
  layerUsed_.assign(shape_.coarseLayers, 0);
  coarse_ = allocZeroed<CoarseCell>(shape_.coarseLayers * cap_.coarseBins);
  coarseSub_ = std::bit_floor(cap_.coarseBins);
  if (pool_) pool_->reserveAlways(reserved_ = cap_.bytes);
}

PathCacheStore::~PathCacheStore() {
  if (pool_) pool_->release(reserved_);
}

size_t PathCacheStore::coarseBytes() const {
  return maxCap_.bytes - maxCap_.entries * kPathEntryBytes -
         maxCap_.indexSlots * PathIndex::kSlotBytes - maxCap_.windowTerms * shape_.termBytes;
}

PathCacheStore::Capacity PathCacheStore::tablesFor(size_t tableBudget) const {
  const size_t fixed = coarseBytes();
  if (fixed + tableBudget >= budget_) return maxCap_;
  // Split a budget of the coarse store plus tableBudget, then keep the whole budget's coarse
  // store (capacityFor gives a smaller budget a smaller one).
  std::optional<Capacity> split = splitBudget(shape_, fixed + tableBudget);
  if (!split || split->entries >= maxCap_.entries) return maxCap_;
  Capacity c = *split;
  c.coarseBins = maxCap_.coarseBins;
  c.bytes = fixed + c.entries * kPathEntryBytes + c.indexSlots * PathIndex::kSlotBytes +
            c.windowTerms * shape_.termBytes;
  return c;
}

bool PathCacheStore::grow() {
  const Capacity next = tablesFor(2 * (cap_.bytes - coarseBytes()));
  if (next.entries <= cap_.entries) return false;
  const size_t extra = next.bytes - cap_.bytes;
  if (pool_ && !pool_->tryReserve(extra, frameTake_)) {
    growthDeferred_ = true;  // counted as refused only if the retry between frames fails too
    return false;
  }
  reserved_ += pool_ ? extra : 0;
  cap_ = next;
  resizeTables();  // the index anew (slots are placed by hash), the window terms in order
  return true;
}

}  // namespace dpc
