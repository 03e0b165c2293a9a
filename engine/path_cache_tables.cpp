// DiffusePathCache's tables: how a budget is split (capacityFor), their allocation at
// construction and their growth from the cache pool (grow). The estimator itself (the
// weightings, merges and readout) is engine/path_cache.cpp.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>

#include "engine/path_cache.h"

namespace dpc {

namespace {

uint32_t lifetimeFor(DpcWeighting w, double tau, double period, double& a) {
  a = 1.0;
  if (w == DpcWeighting::kEma) {
    a = tau > 0.0 ? 1.0 - std::exp(-period / tau) : 1.0;
    // Read out at the frame of the last hit and M more frames, (1-a)^M <= drop fraction.
    return a >= 1.0 ? 1u
                    : 1u + uint32_t(std::ceil(std::log(DiffusePathCache::kEmaDropFraction) /
                                              std::log(1.0 - a)));
  }
  // Seed: read out in the creation frame and until tau old; window: W = round(tau / T) frames.
  return uint32_t(std::max(1.0, std::round(tau / period)));
}

template <class T>
T* allocZeroed(size_t n) {
  if (n == 0) return nullptr;
  void* p = std::calloc(n, sizeof(T));
  if (!p) throw std::bad_alloc();
  return static_cast<T*>(p);
}

/// Writes one byte per 4 KiB of p[0, bytes) so the pages are committed now. The index is hashed,
/// so a table in use touches all its pages within a few frames anyway; committing them at
/// construction keeps those first frames free of page faults (each a read fault mapping the
/// shared zero page, then a copy-on-write fault whose TLB flush interrupts every core).
void commitPages(void* p, size_t bytes) {
  volatile unsigned char* c = static_cast<unsigned char*>(p);
  for (size_t i = 0; i < bytes; i += 4096) c[i] = 0;
}

}  // namespace

void DiffusePathCache::FreeDeleter::operator()(void* p) const {
  std::free(p);
}

std::optional<DiffusePathCache::Capacity> DiffusePathCache::splitBudget(DpcWeighting weighting,
                                                                        double tauSeconds,
                                                                        double framePeriodSeconds,
                                                                        size_t budgetBytes) {
  double a = 1.0;
  const size_t lifetime = lifetimeFor(weighting, tauSeconds, framePeriodSeconds, a);
  const bool window = weighting == DpcWeighting::kWindow;
  const size_t layers = weighting == DpcWeighting::kEma ? 1 : lifetime;
  // Fixed tables: the rays ring, the age histogram, seed layer stamps, window slot counts.
  const size_t fixed = (lifetime + 1) * sizeof(uint64_t) + (lifetime + 1) * sizeof(uint32_t) +
                       layers * sizeof(uint32_t) + (window ? lifetime * sizeof(uint32_t) : 0);
  Capacity c;
  const size_t perBin = layers * sizeof(Cell);
  c.coarseBins = std::min(kMaxCoarseBins, std::min(budgetBytes, kCoarseBudgetBytes) / 4 / perBin);
  const size_t perEntry = sizeof(Entry) + (window ? 2 * sizeof(WindowTerm) : 0);
  const size_t used = fixed + c.coarseBins * perBin;
  if (c.coarseBins == 0 || used >= budgetBytes) return std::nullopt;
  const size_t rest = budgetBytes - used;
  // Index slots a power of two at load <= 3/4: pick the size that holds the most entries.
  for (size_t slots = 2; slots * sizeof(IndexSlot) < rest; slots *= 2) {
    const size_t e = std::min(slots / 4 * 3, (rest - slots * sizeof(IndexSlot)) / perEntry);
    if (e > c.entries) c.entries = e, c.indexSlots = slots;
  }
  if (c.entries == 0) return std::nullopt;
  c.windowTerms = window ? 2 * c.entries : 0;
  c.bytes = used + c.entries * sizeof(Entry) + c.indexSlots * sizeof(IndexSlot) +
            c.windowTerms * sizeof(WindowTerm);
  return c;
}

DiffusePathCache::Capacity DiffusePathCache::capacityFor(DpcWeighting weighting, double tauSeconds,
                                                         double framePeriodSeconds,
                                                         size_t budgetBytes) {
  if (!(tauSeconds >= 0.0) || !(framePeriodSeconds > 0.0))
    throw std::invalid_argument("DiffusePathCache: tau must be >= 0 and frame period > 0");
  if (auto c = splitBudget(weighting, tauSeconds, framePeriodSeconds, budgetBytes)) return *c;
  // The smallest budget that holds one path entry and one coarse bin (a larger budget gives
  // every table at least as much): beyond 2^40 bytes, the frames tau keeps are too many.
  size_t lo = budgetBytes, hi = size_t(1) << 40;
  if (!splitBudget(weighting, tauSeconds, framePeriodSeconds, hi)) {
    double a = 1.0;
    throw std::invalid_argument(
        "cache_tau: " + std::to_string(lifetimeFor(weighting, tauSeconds, framePeriodSeconds, a)) +
        " frames of paths (cache_tau x frame_rate) are more than the path cache's coarse store "
        "holds (" +
        std::to_string(kCoarseBudgetBytes / 4 / sizeof(Cell)) + "): lower cache_tau or frame_rate");
  }
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    (splitBudget(weighting, tauSeconds, framePeriodSeconds, mid) ? hi : lo) = mid;
  }
  throw std::invalid_argument("cache_memory_mb: a budget of " + std::to_string(budgetBytes) +
                              " bytes per source-listener pair is below the " + std::to_string(hi) +
                              " this cache_tau and frame_rate need (MB = 1048576 bytes)");
}

DiffusePathCache::DiffusePathCache(DpcWeighting weighting, double tauSeconds,
                                   double framePeriodSeconds, size_t budgetBytes, CachePool* pool)
    : weighting_(weighting),
      budget_(budgetBytes),
      tau_(tauSeconds),
      period_(framePeriodSeconds),
      pool_(pool) {
  maxCap_ = capacityFor(weighting, tauSeconds, framePeriodSeconds, budgetBytes);
  cap_ = tablesFor(kInitialTableBytes);
  lifetime_ = lifetimeFor(weighting, tauSeconds, framePeriodSeconds, a_);
  layers_ = weighting_ == DpcWeighting::kEma ? 1 : lifetime_;
  raysBefore_.assign(size_t(lifetime_) + 1, 0);
  ageCount_.assign(size_t(lifetime_) + 1, 0);
  layerStamp_.assign(layers_, 0);
  layerUsed_.assign(layers_, 0);
  if (weighting_ == DpcWeighting::kWindow) slotTerms_.assign(lifetime_, 0);
  coarse_.reset(allocZeroed<Cell>(layers_ * cap_.coarseBins));
  index_.reset(allocZeroed<IndexSlot>(cap_.indexSlots));
  commitPages(index_.get(), cap_.indexSlots * sizeof(IndexSlot));
  indexShift_ = 64 - int(std::countr_zero(cap_.indexSlots));
  entries_.reserve(cap_.entries);
  terms_.reset(allocZeroed<WindowTerm>(cap_.windowTerms));
  coarseSub_ = std::bit_floor(cap_.coarseBins);
  if (pool_) pool_->reserveAlways(reserved_ = cap_.bytes);
}

DiffusePathCache::~DiffusePathCache() {
  if (pool_) pool_->release(reserved_);
}

size_t DiffusePathCache::coarseBytes() const {
  return maxCap_.bytes - maxCap_.entries * sizeof(Entry) - maxCap_.indexSlots * sizeof(IndexSlot) -
         maxCap_.windowTerms * sizeof(WindowTerm);
}

DiffusePathCache::Capacity DiffusePathCache::tablesFor(size_t tableBudget) const {
  const size_t fixed = coarseBytes();
  if (fixed + tableBudget >= budget_) return maxCap_;
  // Split a budget of the coarse store plus tableBudget, then keep the whole budget's coarse
  // store (capacityFor gives a smaller budget a smaller one).
  std::optional<Capacity> split = splitBudget(weighting_, tau_, period_, fixed + tableBudget);
  if (!split || split->entries >= maxCap_.entries) return maxCap_;
  Capacity c = *split;
  c.coarseBins = maxCap_.coarseBins;
  c.bytes = fixed + c.entries * sizeof(Entry) + c.indexSlots * sizeof(IndexSlot) +
            c.windowTerms * sizeof(WindowTerm);
  return c;
}

bool DiffusePathCache::grow() {
  const Capacity next = tablesFor(2 * (cap_.bytes - coarseBytes()));
  if (next.entries <= cap_.entries) return false;
  const size_t extra = next.bytes - cap_.bytes;
  if (pool_ && !pool_->tryReserve(extra)) {
    ++refused_;
    return false;
  }
  reserved_ += pool_ ? extra : 0;
  // The index anew (slots are placed by hash), the ring of window terms in order from its head.
  index_.reset(allocZeroed<IndexSlot>(next.indexSlots));
  commitPages(index_.get(), next.indexSlots * sizeof(IndexSlot));
  const size_t oldTerms = cap_.windowTerms;
  cap_ = next;
  indexShift_ = 64 - int(std::countr_zero(cap_.indexSlots));
  for (size_t i = 0; i < entries_.size(); ++i) indexInsert(entries_[i].key, uint32_t(i));
  entries_.reserve(cap_.entries);
  if (cap_.windowTerms > 0) {
    Buffer<WindowTerm> terms(allocZeroed<WindowTerm>(cap_.windowTerms));
    for (size_t k = 0; k < termCount_; ++k) terms[k] = terms_[(termHead_ + k) % oldTerms];
    terms_ = std::move(terms);
    termHead_ = 0;
  }
  return true;
}

}  // namespace dpc
