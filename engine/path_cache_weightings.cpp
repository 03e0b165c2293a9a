#include "engine/path_cache_weightings.h"

#include <algorithm>

namespace dpc {

namespace {

/// lastHit of a window entry that makeRoom merges: its terms go to the coarse store, then the
/// entry is removed (no frame number reaches it).
constexpr uint32_t kMergedFrame = 0xFFFFFFFFu;

/// The oldest ageFrame() of `entries`, or `frames` when there is none.
template <class Entry>
uint32_t oldestFrame(const std::vector<Entry>& entries, uint32_t frames) {
  uint32_t oldest = frames;
  for (const Entry& e : entries) oldest = std::min(oldest, e.ageFrame());
  return oldest;
}

}  // namespace

std::unique_ptr<PathCacheStore> makeWeightedStore(DpcWeighting weighting, double tauSeconds,
                                                  double framePeriodSeconds, size_t budgetBytes,
                                                  CachePool* pool) {
  switch (weighting) {
    case DpcWeighting::kSeed:
      return std::make_unique<SeedCache>(tauSeconds, framePeriodSeconds, budgetBytes, pool);
    case DpcWeighting::kEma:
      return std::make_unique<EmaCache>(tauSeconds, framePeriodSeconds, budgetBytes, pool);
    case DpcWeighting::kWindow:
      break;
  }
  return std::make_unique<WindowCache>(tauSeconds, framePeriodSeconds, budgetBytes, pool);
}

// ---------------------------------------------------------------------------------------
// Seed

SeedCache::SeedCache(double tauSeconds, double framePeriodSeconds, size_t budgetBytes,
                     CachePool* pool)
    : PathCacheStore(DpcWeighting::kSeed, tauSeconds, framePeriodSeconds, budgetBytes, pool) {
  table_.resize(cap_.indexSlots, cap_.entries);
  layerCreated_.assign(shape_.coarseLayers, 0);
}

uint32_t SeedCache::oldestEntryFrame() const {
  return oldestFrame(table_.entries(), frame_);
}

void SeedCache::resizeTables() {
  table_.resize(cap_.indexSlots, cap_.entries);
}

void SeedCache::clearEntries() {
  table_.clear();
  std::fill(layerCreated_.begin(), layerCreated_.end(), 0);
}

void SeedCache::applyFrame(const FrameGroups& frame, float, double invC, EnergyResponse& out,
                           ArrivalSink* directional, double& total, double& coarse) {
  // Eq. 3.4, applied to the frame's hits of each path at once (the same sums).
  for (const FrameGroups::Group& g : frame.groups()) {
    makeRoomFor(table_, g.key, invC);
    bool inserted = false;
    SeedEntry* e = table_.findOrInsert(g.key, frame_, inserted);
    if (inserted) {
      e->hits = float(g.eta);
      e->intensitySum = g.intensity;
      e->lengthSum = g.length;
      e->directionSum = g.direction;
    } else {
      e->hits += float(g.eta);
      e->intensitySum += g.intensity;
      e->lengthSum += g.length;
      e->directionSum += g.direction;
    }
  }
  // mu: rays emitted from the frame that created the entry (or layer) through this one.
  for (const SeedEntry& e : table_.entries()) {
    const double delay = meanDelaySeconds(e.lengthSum, e.hits, invC);  // eq. 3.3
    out.add(delay, e.intensitySum / raysSince(e.created));             // eq. 3.2
    if (directional) directional->add(delay, e.intensitySum / raysSince(e.created), e.directionSum);
    total += double((e.intensitySum / raysSince(e.created)).average());
  }
  for (size_t l = 0; l < shape_.coarseLayers; ++l)
    for (size_t b = 0; layerUsed_[l] && b < cap_.coarseBins; ++b)
      if (cell(l, b).hits > 0.f)
        readCell(cell(l, b), b, raysSince(layerCreated_[l]), invC, out, directional, coarse);
  expire();
}

void SeedCache::makeRoom(double invC) {
  OldestCut cut = oldestCut(table_.entries());
  std::vector<SeedEntry>& entries = table_.entries();
  for (size_t i = entries.size(); i-- > 0;) {
    const SeedEntry& e = entries[i];
    if (!cut.takes(ageOf(e.created))) continue;
    ++merged_;
    const double delay = e.hits > 0.f ? meanDelaySeconds(e.lengthSum, e.hits, invC) : 0.0;
    const size_t bin = coarseBin(delay);
    const size_t layer = e.created % shape_.coarseLayers;
    layerCreated_[layer] = e.created;
    layerUsed_[layer] = 1;
    CoarseCell& c = cell(layer, bin);
    c.intensity += e.intensitySum;
    c.length += e.lengthSum;
    c.hits += e.hits;
    c.direction += e.directionSum;
    table_.removeAt(i);
  }
}

void SeedCache::expire() {
  std::vector<SeedEntry>& entries = table_.entries();
  const uint32_t lifetime = shape_.lifetime;
  for (size_t i = entries.size(); i-- > 0;)
    if (frame_ - entries[i].created + 1 >= lifetime) table_.removeAt(i);
  // The layer created L - 1 frames ago has been read out L times.
  const uint32_t l = (frame_ + 1) % lifetime;
  if (frame_ + 1 >= lifetime && layerCreated_[l] + lifetime <= frame_ + 1 && layerUsed_[l])
    clearLayer(l);
}

// ---------------------------------------------------------------------------------------
// EMA

EmaCache::EmaCache(double tauSeconds, double framePeriodSeconds, size_t budgetBytes,
                   CachePool* pool)
    : PathCacheStore(DpcWeighting::kEma, tauSeconds, framePeriodSeconds, budgetBytes, pool) {
  table_.resize(cap_.indexSlots, cap_.entries);
}

uint32_t EmaCache::oldestEntryFrame() const {
  return oldestFrame(table_.entries(), frame_);
}

void EmaCache::resizeTables() {
  table_.resize(cap_.indexSlots, cap_.entries);
}

void EmaCache::clearEntries() {
  table_.clear();
  decayPow_ = 1.0;
}

void EmaCache::applyFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                          ArrivalSink* directional, double& total, double& coarse) {
  const double a = shape_.emaCoefficient;
  const float keep = float(1.0 - a), af = float(a);
  for (EmaEntry& e : table_.entries()) {
    e.meanEstimate *= keep;
    e.meanLength *= keep;
    e.meanHits *= keep;
    e.meanDirection *= keep;
  }
  for (size_t b = 0; layerUsed_[0] && b < cap_.coarseBins; ++b) {
    CoarseCell& c = cell(0, b);
    c.intensity *= keep;
    c.length *= keep;
    c.hits *= keep;
    c.direction *= keep;
  }
  for (const FrameGroups::Group& g : frame.groups()) {
    makeRoomFor(table_, g.key, invC);
    bool inserted = false;
    EmaEntry* e = table_.findOrInsert(g.key, frame_, inserted);
    e->meanEstimate += (g.intensity / n) * af;
    e->meanLength += g.length * af;
    e->meanHits += float(g.eta) * af;
    e->meanDirection += g.direction * af;
    e->lastHit = frame_;
  }
  decayPow_ *= 1.0 - a;
  const float norm = float(1.0 - decayPow_);
  for (const EmaEntry& e : table_.entries()) {
    const double delay = meanDelaySeconds(e.meanLength, e.meanHits, invC);
    out.add(delay, e.meanEstimate / norm);
    if (directional) directional->add(delay, e.meanEstimate / norm, e.meanDirection);
    total += double((e.meanEstimate / norm).average());
  }
  for (size_t b = 0; layerUsed_[0] && b < cap_.coarseBins; ++b)
    if (cell(0, b).hits > 0.f) readCell(cell(0, b), b, norm, invC, out, directional, coarse);
  expire();
}

void EmaCache::makeRoom(double invC) {
  OldestCut cut = oldestCut(table_.entries());
  std::vector<EmaEntry>& entries = table_.entries();
  for (size_t i = entries.size(); i-- > 0;) {
    const EmaEntry& e = entries[i];
    if (!cut.takes(ageOf(e.lastHit))) continue;
    ++merged_;
    const double delay = e.meanHits > 0.f ? meanDelaySeconds(e.meanLength, e.meanHits, invC) : 0.0;
    const size_t bin = coarseBin(delay);
    layerUsed_[0] = 1;
    CoarseCell& c = cell(0, bin);
    c.intensity += e.meanEstimate;
    c.length += e.meanLength;
    c.hits += e.meanHits;
    c.direction += e.meanDirection;
    c.lastHit = std::max(c.lastHit, e.lastHit);  // the cell expires with its newest member
    table_.removeAt(i);
  }
}

void EmaCache::expire() {
  std::vector<EmaEntry>& entries = table_.entries();
  const uint32_t lifetime = shape_.lifetime;
  for (size_t i = entries.size(); i-- > 0;)
    if (frame_ - entries[i].lastHit + 1 >= lifetime) table_.removeAt(i);
  if (!layerUsed_[0]) return;
  size_t live = 0;
  for (size_t b = 0; b < cap_.coarseBins; ++b) {
    if (!(cell(0, b).hits > 0.f)) continue;
    if (frame_ - cell(0, b).lastHit + 1 >= lifetime)
      cell(0, b) = CoarseCell{};
    else
      ++live;
  }
  layerUsed_[0] = live > 0;
}

// ---------------------------------------------------------------------------------------
// Window

WindowCache::WindowCache(double tauSeconds, double framePeriodSeconds, size_t budgetBytes,
                         CachePool* pool)
    : PathCacheStore(DpcWeighting::kWindow, tauSeconds, framePeriodSeconds, budgetBytes, pool) {
  table_.resize(cap_.indexSlots, cap_.entries);
  slotTerms_.assign(shape_.lifetime, 0);
  terms_ = allocZeroed<WindowTerm>(cap_.windowTerms);
  ringSize_ = std::min(cap_.windowTerms, kRingStep);
}

uint32_t WindowCache::oldestEntryFrame() const {
  return oldestFrame(table_.entries(), frame_);
}

void WindowCache::resizeTables() {
  table_.resize(cap_.indexSlots, cap_.entries);
  // The ring of window terms in order from its head.
  Buffer<WindowTerm> terms = allocZeroed<WindowTerm>(cap_.windowTerms);
  for (size_t k = 0; k < termCount_; ++k) terms[k] = terms_[(termHead_ + k) % ringSize_];
  terms_ = std::move(terms);
  termHead_ = 0;
  ringSize_ = std::min(cap_.windowTerms, termCount_ + kRingStep);
}

void WindowCache::widenRing() {
  // Full, so the ring is the whole of [0, ringSize_) from termHead_ on: rotated to start at
  // 0, it grows at its end.
  std::rotate(terms_.get(), terms_.get() + termHead_, terms_.get() + ringSize_);
  termHead_ = 0;
  ringSize_ = std::min(cap_.windowTerms, ringSize_ + std::max(ringSize_ / 4, kRingStep));
}

void WindowCache::clearEntries() {
  table_.clear();
  std::fill(slotTerms_.begin(), slotTerms_.end(), 0);
  termHead_ = termCount_ = 0;
}

size_t WindowCache::unusedTermBytes() const {
  return (cap_.windowTerms - termCount_) * sizeof(WindowTerm);
}

void WindowCache::applyFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                             ArrivalSink* directional, double& total, double& coarse) {
  const size_t slot = slotOf(frame_);
  if (frame_ >= shape_.lifetime) retireSlot(slot);
  slotTerms_[slot] = 0;
  for (const FrameGroups::Group& g : frame.groups()) {
    if (termCount_ == ringSize_ && ringSize_ < cap_.windowTerms) widenRing();
    if (termCount_ == cap_.windowTerms) {
      if (!grow()) makeRoom(invC);
    } else {
      makeRoomFor(table_, g.key, invC);
    }
    bool inserted = false;
    WindowEntry* e = table_.findOrInsert(g.key, frame_, inserted);
    const Bands i = g.intensity / n;
    e->estimateSum += i;
    e->lengthSum += g.length;
    e->hits += float(g.eta);
    e->directionSum += g.direction;
    e->lastHit = frame_;
    terms_[(termHead_ + termCount_) % ringSize_] = {g.key, i, g.length, float(g.eta),
                                                           g.direction};
    ++termCount_;
    ++slotTerms_[slot];
  }
  // Mean over the frames in the window so far (fewer than W at the start: still unbiased).
  readOut(float(std::min<uint64_t>(uint64_t(frame_) + 1, shape_.lifetime)), invC, out,
          directional, total, coarse);
}

void WindowCache::readOut(float frames, double invC, EnergyResponse& out,
                          ArrivalSink* directional, double& total, double& coarse) const {
  for (const WindowEntry& e : table_.entries()) {
    const double delay = meanDelaySeconds(e.lengthSum, e.hits, invC);
    const Bands mean = e.estimateSum / frames;  // once: out.add may alias e for the compiler
    out.add(delay, mean);
    if (directional) directional->add(delay, mean, e.directionSum);
    total += double(mean.average());
  }
  const bool anyCoarse = std::find(layerUsed_.begin(), layerUsed_.end(), 1) != layerUsed_.end();
  for (size_t b = 0; anyCoarse && b < cap_.coarseBins; ++b) {
    CoarseCell sum{};
    for (size_t l = 0; l < shape_.coarseLayers; ++l) {
      if (!layerUsed_[l]) continue;
      const CoarseCell& c = coarseCell(l, b);
      sum.intensity += c.intensity;
      sum.length += c.length;
      sum.hits += c.hits;
      sum.direction += c.direction;
    }
    if (sum.hits > 0.5f) readCell(sum, b, frames, invC, out, directional, coarse);
  }
}

void WindowCache::makeRoom(double invC) {
  for (;;) {
    OldestCut cut = oldestCut(table_.entries());
    std::vector<WindowEntry>& entries = table_.entries();
    // Marked here; their terms move to the coarse rows below, then they go.
    for (size_t i = entries.size(); i-- > 0;) {
      if (!cut.takes(ageOf(entries[i].lastHit))) continue;
      ++merged_;
      entries[i].lastHit = kMergedFrame;
    }
    mergeMarkedTerms(invC);
    if (termCount_ < cap_.windowTerms) return;
  }
}

void WindowCache::mergeMarkedTerms(double invC) {
  // Walk the ring oldest frame first; terms of marked entries go to the coarse row of their
  // frame (retired with it), the others are compacted towards the head.
  const uint32_t lifetime = shape_.lifetime;
  const uint64_t first = frame_ + 1 > lifetime ? uint64_t(frame_) + 1 - lifetime : 0;
  size_t r = termHead_, w = termHead_;
  for (uint64_t f = first; f <= frame_; ++f) {
    uint32_t& n = slotTerms_[slotOf(f)];
    uint32_t kept = 0;
    for (uint32_t k = 0; k < n; ++k, r = (r + 1) % ringSize_) {
      const WindowTerm t = terms_[r];
      const WindowEntry& e = table_.entries()[table_.indexOf(t.key)];
      if (e.lastHit != kMergedFrame) {
        terms_[w] = t;
        w = (w + 1) % ringSize_;
        ++kept;
        continue;
      }
      const size_t bin = coarseBin(meanDelaySeconds(e.lengthSum, e.hits, invC));
      layerUsed_[slotOf(f)] = 1;
      CoarseCell& c = cell(slotOf(f), bin);
      c.intensity += t.estimate;
      c.length += t.length;
      c.hits += t.hits;
      c.direction += t.direction;
    }
    termCount_ -= n - kept;
    n = kept;
  }
  std::vector<WindowEntry>& entries = table_.entries();
  for (size_t i = entries.size(); i-- > 0;)
    if (entries[i].lastHit == kMergedFrame) table_.removeAt(i);
}

void WindowCache::retireSlot(size_t slot) {
  // Frame f0 = frame_ - W: its path terms are the oldest in the ring; subtract each from its
  // entry and remove entries left without hits (hit counts are integers, so eta reaches 0
  // exactly); its coarse row is cleared.
  for (uint32_t k = 0; k < slotTerms_[slot]; ++k) {
    const WindowTerm& t = terms_[termHead_];
    termHead_ = (termHead_ + 1) % ringSize_;
    const uint32_t i = table_.indexOf(t.key);
    WindowEntry& e = table_.entries()[i];
    e.hits -= t.hits;
    e.estimateSum -= t.estimate;
    // The true sum of the remaining non-negative terms is >= 0; rounding of the add-then-
    // subtract can leave a residue below 0 (1 + 1e-8 - 1 - 1e-8 in float), which no
    // energy may hold.
    for (int b = 0; b < kNumBands; ++b) e.estimateSum[b] = std::max(e.estimateSum[b], 0.f);
    e.lengthSum -= t.length;
    e.directionSum -= t.direction;
    if (e.hits <= 0.5f) table_.removeAt(i);
  }
  termCount_ -= slotTerms_[slot];
  clearLayer(slot);
}

}  // namespace dpc
