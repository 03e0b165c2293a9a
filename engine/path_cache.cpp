#include "engine/path_cache.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <new>
#include <stdexcept>
#include <string>

namespace dpc {

void FrameGroups::clear() {
  index_.clear();
  groups_.clear();
  hits_ = 0;
}

void FrameGroups::add(const PathHit& hit) {
  ++hits_;
  const float w = hit.intensity.average();
  auto [it, inserted] = index_.try_emplace(hit.key, uint32_t(groups_.size()));
  if (inserted) {
    groups_.push_back({hit.key, 1u, hit.intensity, hit.length, hit.direction * w});
    return;
  }
  Group& g = groups_[it->second];
  g.eta += 1;
  g.intensity += hit.intensity;
  g.length += hit.length;
  g.direction += hit.direction * w;
}

void PathTracingEstimator::endFrame(const FrameGroups& frame, uint64_t raysEmitted,
                                    float speedOfSound, EnergyResponse& out,
                                    ArrivalSink* directional) const {
  // The same expressions as DiffusePathCache::endFrame, so that tau = 0 matches bit for bit.
  const float n = float(raysEmitted);
  const double invC = 1.0 / double(speedOfSound);
  for (const FrameGroups::Group& g : frame.groups()) {
    const double delay = meanDelaySeconds(g.length, float(g.eta), invC);
    out.add(delay, g.intensity / n);
    if (directional) directional->add(delay, g.intensity / n, g.direction);
  }
}

namespace {

/// Stamp of a kWindow entry that makeRoom merges: its terms go to the coarse store, then the
/// entry is removed (no frame number reaches it).
constexpr uint32_t kMergedStamp = 0xFFFFFFFFu;

}  // namespace

void DiffusePathCache::clear() {
  for (const Entry& e : entries_) indexErase(e.key);
  entries_.clear();
  std::fill(coarse_.get(), coarse_.get() + layers_ * cap_.coarseBins, Cell{});
  coarseSub_ = std::bit_floor(cap_.coarseBins);
  coarseFraction_ = 0.0;
  frame_ = 0;
  decayPow_ = 1.0;
  raysTotal_ = 0;
  std::fill(raysBefore_.begin(), raysBefore_.end(), 0);
  std::fill(layerStamp_.begin(), layerStamp_.end(), 0);
  std::fill(layerUsed_.begin(), layerUsed_.end(), 0);
  std::fill(slotTerms_.begin(), slotTerms_.end(), 0);
  termHead_ = termCount_ = 0;
}

size_t DiffusePathCache::coarseEntryCount() const {
  size_t n = 0;
  for (size_t l = 0; l < layers_; ++l)
    if (layerUsed_[l])
      for (size_t b = 0; b < cap_.coarseBins; ++b) n += coarse_[l * cap_.coarseBins + b].eta > 0.f;
  return n;
}

size_t DiffusePathCache::bytesInUse() const {
  return cap_.bytes - (cap_.entries - entries_.size()) * sizeof(Entry) -
         (cap_.windowTerms - termCount_) * sizeof(WindowTerm);
}

// Open-addressing index: Fibonacci hashing of the key (test keys are small integers), linear
// probing, backward-shift deletion (no tombstones, so probe lengths stay short at load 3/4).
size_t DiffusePathCache::indexFind(uint64_t key) const {
  const size_t mask = cap_.indexSlots - 1;
  for (size_t i = size_t((key * 0x9E3779B97F4A7C15ull) >> indexShift_);; i = (i + 1) & mask) {
    if (index_[i].index1 == 0) return cap_.indexSlots;
    if (index_[i].key == key) return i;
  }
}

uint32_t DiffusePathCache::indexOf(uint64_t key) const {
  return index_[indexFind(key)].index1 - 1;
}

void DiffusePathCache::indexInsert(uint64_t key, uint32_t index) {
  const size_t mask = cap_.indexSlots - 1;
  size_t i = size_t((key * 0x9E3779B97F4A7C15ull) >> indexShift_);
  while (index_[i].index1 != 0 && index_[i].key != key) i = (i + 1) & mask;
  index_[i] = {key, index + 1};
}

void DiffusePathCache::indexErase(uint64_t key) {
  const size_t mask = cap_.indexSlots - 1;
  size_t i = indexFind(key);
  if (i == cap_.indexSlots) return;
  for (size_t j = (i + 1) & mask; index_[j].index1 != 0; j = (j + 1) & mask) {
    const size_t home = size_t((index_[j].key * 0x9E3779B97F4A7C15ull) >> indexShift_);
    // Move j back into the hole at i unless its home lies cyclically in (i, j].
    const bool stays = i <= j ? (i < home && home <= j) : (i < home || home <= j);
    if (stays) continue;
    index_[i] = index_[j];
    i = j;
  }
  index_[i].index1 = 0;
}

DiffusePathCache::Entry* DiffusePathCache::findOrInsert(uint64_t key, bool& inserted) {
  const size_t slot = indexFind(key);
  inserted = slot == cap_.indexSlots;
  if (!inserted) return &entries_[index_[slot].index1 - 1];
  indexInsert(key, uint32_t(entries_.size()));
  entries_.push_back(Entry{key, frame_, 0.f, Bands(0.f), 0.f, glm::vec3(0.f)});
  return &entries_.back();
}

void DiffusePathCache::removeAt(size_t i) {
  indexErase(entries_[i].key);
  if (i + 1 != entries_.size()) {
    entries_[i] = entries_.back();
    index_[indexFind(entries_[i].key)].index1 = uint32_t(i) + 1;
  }
  entries_.pop_back();
}

size_t DiffusePathCache::binOf(uint64_t fine, size_t sub) {
  if (fine < sub) return size_t(fine);
  const int k = std::bit_width(fine / sub) - 1;  // octave: fine in [sub 2^k, sub 2^(k+1))
  return sub * size_t(k) + size_t(fine >> k);
}

size_t DiffusePathCache::coarseBin(double delaySeconds) {
  const uint64_t fine = uint64_t(std::min(std::max(0.0, delaySeconds / kCoarseBinSeconds), 1e15));
  while (binOf(fine, coarseSub_) >= cap_.coarseBins && coarseSub_ > 1) widenCoarse();
  // One bin per octave and still beyond: the last bin (only with a handful of bins).
  return std::min(binOf(fine, coarseSub_), cap_.coarseBins - 1);
}

void DiffusePathCache::widenCoarse() {
  // Halving S: every new bin is the union of old bins (octave k of S is octave k + 1 of S / 2,
  // bins twice as wide), so cells only add up and no energy leaves the store. New indices are
  // never above old ones, so an ascending pass moves each cell once.
  const size_t nb = cap_.coarseBins, sub = coarseSub_ / 2;
  for (size_t b = 0; b < nb; ++b) {
    const size_t to = binOf(binStart(b, coarseSub_), sub);
    if (to == b) continue;
    for (size_t l = 0; l < layers_; ++l) {
      const Cell src = cell(l, b);
      cell(l, b) = Cell{};
      Cell& d = cell(l, to);
      d.intensity += src.intensity;
      d.length += src.length;
      d.eta += src.eta;
      d.direction += src.direction;
      d.stamp = std::max(d.stamp, src.stamp);
    }
  }
  coarseSub_ = sub;
}

void DiffusePathCache::makeRoom(double invC) {
  // Oldest first: ages (frames since stamp) are < lifetime_ for live entries. Merge the entries
  // of the oldest ages until at least an eighth of the table (and one entry) is merged.
  const size_t target = std::max<size_t>(1, cap_.entries / 8);
  const bool window = weighting_ == DpcWeighting::kWindow;
  for (;;) {
    std::fill(ageCount_.begin(), ageCount_.end(), 0);
    for (const Entry& e : entries_) ++ageCount_[std::min<size_t>(frame_ - e.stamp, lifetime_)];
    size_t thr = ageCount_.size(), count = 0;
    while (thr > 0 && count < target) count += ageCount_[--thr];
    size_t quota = ageCount_[thr] - (count - std::min(count, target));  // of age == thr
    for (size_t i = entries_.size(); i-- > 0;) {
      Entry& e = entries_[i];
      const size_t age = std::min<size_t>(frame_ - e.stamp, lifetime_);
      if (age < thr || (age == thr && quota == 0)) continue;
      if (age == thr) --quota;
      ++merged_;
      if (window) {  // its terms move to the coarse rows below; the entry goes after that
        e.stamp = kMergedStamp;
        continue;
      }
      const double delay = e.eta > 0.f ? meanDelaySeconds(e.length, e.eta, invC) : 0.0;
      const size_t bin = coarseBin(delay);
      size_t layer = 0;
      if (weighting_ == DpcWeighting::kSeed) {
        // Seed cells merge only entries of one creation frame: mu and the lifetime are shared
        // and I_hat / mu stays exactly additive.
        layer = e.stamp % layers_;
        layerStamp_[layer] = e.stamp;
      }
      layerUsed_[layer] = 1;
      Cell& c = cell(layer, bin);
      c.intensity += e.intensity;
      c.length += e.length;
      c.eta += e.eta;
      c.direction += e.direction;
      c.stamp = std::max(c.stamp, e.stamp);  // EMA: expires with the newest member's last hit
      removeAt(i);
    }
    if (!window) return;
    mergeMarkedTerms(invC);
    if (termCount_ < cap_.windowTerms) return;
  }
}

void DiffusePathCache::mergeMarkedTerms(double invC) {
  // Walk the ring oldest frame first; terms of marked entries go to the coarse row of their
  // frame (retired with it), the others are compacted towards the head.
  const uint64_t first = frame_ + 1 > lifetime_ ? uint64_t(frame_) + 1 - lifetime_ : 0;
  size_t r = termHead_, w = termHead_;
  for (uint64_t f = first; f <= frame_; ++f) {
    uint32_t& n = slotTerms_[windowSlot(f)];
    uint32_t kept = 0;
    for (uint32_t k = 0; k < n; ++k, r = (r + 1) % cap_.windowTerms) {
      const WindowTerm t = terms_[r];
      const Entry& e = entries_[indexOf(t.key)];
      if (e.stamp != kMergedStamp) {
        terms_[w] = t;
        w = (w + 1) % cap_.windowTerms;
        ++kept;
        continue;
      }
      const size_t bin = coarseBin(meanDelaySeconds(e.length, e.eta, invC));
      layerUsed_[windowSlot(f)] = 1;
      Cell& c = cell(windowSlot(f), bin);
      c.intensity += t.intensity;
      c.length += t.length;
      c.eta += t.eta;
      c.direction += t.direction;
    }
    termCount_ -= n - kept;
    n = kept;
  }
  for (size_t i = entries_.size(); i-- > 0;)
    if (entries_[i].stamp == kMergedStamp) removeAt(i);
}

void DiffusePathCache::readCell(const Cell& c, size_t bin, float divisor, double invC,
                                EnergyResponse& out, ArrivalSink* directional,
                                double& energy) const {
  const Bands i = c.intensity / divisor;
  energy += double(i.average());
  const size_t first = binStart(bin, coarseSub_),
               widthSteps = binStart(bin + 1, coarseSub_) - first;
  if (widthSteps == 1) {  // 1 ms bins: at the hit-weighted mean delay
    const double delay = meanDelaySeconds(c.length, c.eta, invC);
    out.add(delay, i);
    if (directional) directional->add(delay, i, c.direction);
    return;
  }
  // Wider bins: spread over the bin 1 ms at a time with a linear density 1 + s x (x in [-1, 1]
  // across the bin) whose slope s = 6 (mean - centre) / width keeps the hit-weighted mean delay
  // (clamped to |s| <= 1, where the density reaches 0 at one end), so that the late response
  // has no comb of one arrival per bin and follows the decay within the bin. Only the part
  // inside the response is used when the bin runs past its end (the mean delay decides whether
  // the energy is inside at all).
  const double mean = meanDelaySeconds(c.length, c.eta, invC);
  const double end = double(out.binCount()) * out.binSeconds();
  const double width = double(widthSteps) * kCoarseBinSeconds;
  const double centre = (double(first) + 0.5 * double(widthSteps)) * kCoarseBinSeconds;
  const double slope = std::clamp(6.0 * (mean - centre) / width, -1.0, 1.0);
  size_t steps = widthSteps;
  if (mean < end)
    steps = std::clamp<size_t>(size_t(std::ceil(end / kCoarseBinSeconds - 1e-6)) - first, 1, steps);
  auto weight = [&](size_t k) {
    const double t = (double(first + k) + 0.5) * kCoarseBinSeconds;
    return 1.0 + slope * (t - centre) / (0.5 * width);
  };
  double sum = 0.0;
  for (size_t k = 0; k < steps; ++k) sum += weight(k);
  for (size_t k = 0; k < steps; ++k) {
    const double delay = (double(first + k) + 0.5) * kCoarseBinSeconds;
    const Bands part = i * float(weight(k) / sum);
    out.add(delay, part);
    if (directional) directional->add(delay, part, c.direction);
  }
}

void DiffusePathCache::retireWindowSlot(size_t slot) {
  // Frame f0 = frame_ - W: its path terms are the oldest in the ring; subtract each from its
  // entry and remove entries left without hits (hit counts are integers, so eta reaches 0
  // exactly); its coarse row is cleared.
  for (uint32_t k = 0; k < slotTerms_[slot]; ++k) {
    const WindowTerm& t = terms_[termHead_];
    termHead_ = (termHead_ + 1) % cap_.windowTerms;
    const uint32_t i = indexOf(t.key);
    Entry& e = entries_[i];
    e.eta -= t.eta;
    e.intensity -= t.intensity;
    // The true sum of the remaining non-negative terms is >= 0; rounding of the add-then-
    // subtract can leave a residue below 0 (1 + 1e-8 - 1 - 1e-8 in float), which no
    // energy may hold.
    for (int b = 0; b < kNumBands; ++b) e.intensity[b] = std::max(e.intensity[b], 0.f);
    e.length -= t.length;
    e.direction -= t.direction;
    if (e.eta <= 0.5f) removeAt(i);
  }
  termCount_ -= slotTerms_[slot];
  if (layerUsed_[slot]) std::fill(&cell(slot, 0), &cell(slot, 0) + cap_.coarseBins, Cell{});
  layerUsed_[slot] = 0;
}

void DiffusePathCache::readEntries(float divisor, double invC, EnergyResponse& out,
                                   ArrivalSink* directional, double& total) const {
  for (const Entry& e : entries_) {
    const double delay = meanDelaySeconds(e.length, e.eta, invC);
    out.add(delay, e.intensity / divisor);
    if (directional) directional->add(delay, e.intensity / divisor, e.direction);
    total += double((e.intensity / divisor).average());
  }
}

void DiffusePathCache::windowEndFrame(const FrameGroups& frame, float n, double invC,
                                      EnergyResponse& out, ArrivalSink* directional,
                                      double& total, double& coarse) {
  const size_t slot = windowSlot(frame_);
  if (frame_ >= lifetime_) retireWindowSlot(slot);
  slotTerms_[slot] = 0;
  for (const FrameGroups::Group& g : frame.groups()) {
    if (termCount_ == cap_.windowTerms) {
      if (!grow()) makeRoom(invC);
    } else {
      makeRoomFor(g.key, invC);
    }
    bool inserted = false;
    Entry* e = findOrInsert(g.key, inserted);
    const Bands i = g.intensity / n;
    e->intensity += i;
    e->length += g.length;
    e->eta += float(g.eta);
    e->direction += g.direction;
    e->stamp = frame_;
    terms_[(termHead_ + termCount_) % cap_.windowTerms] = {g.key, i, g.length, float(g.eta),
                                                           g.direction};
    ++termCount_;
    ++slotTerms_[slot];
  }
  // Mean over the frames in the window so far (fewer than W at the start: still unbiased).
  const float frames = float(std::min<uint64_t>(uint64_t(frame_) + 1, lifetime_));
  readEntries(frames, invC, out, directional, total);
  const bool anyCoarse = std::find(layerUsed_.begin(), layerUsed_.end(), 1) != layerUsed_.end();
  for (size_t b = 0; anyCoarse && b < cap_.coarseBins; ++b) {
    Cell sum{};
    for (size_t l = 0; l < layers_; ++l) {
      if (!layerUsed_[l]) continue;
      const Cell& c = cell(l, b);
      sum.intensity += c.intensity;
      sum.length += c.length;
      sum.eta += c.eta;
      sum.direction += c.direction;
    }
    if (sum.eta > 0.5f) readCell(sum, b, frames, invC, out, directional, coarse);
  }
}

void DiffusePathCache::endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                                EnergyResponse& out, ArrivalSink* directional) {
  const float n = float(raysEmitted);
  const double invC = 1.0 / double(speedOfSound);
  raysBefore_[frame_ % raysBefore_.size()] = raysTotal_;
  raysTotal_ += raysEmitted;
  double total = 0.0, coarse = 0.0;  // band-average energy read out: all, from the coarse store
  if (weighting_ == DpcWeighting::kWindow)
    windowEndFrame(frame, n, invC, out, directional, total, coarse);
  else if (weighting_ == DpcWeighting::kSeed)
    seedEndFrame(frame, invC, out, directional, total, coarse);
  else
    emaEndFrame(frame, n, invC, out, directional, total, coarse);
  total += coarse;
  coarseFraction_ = total > 0.0 ? coarse / total : 0.0;
  if (weighting_ != DpcWeighting::kWindow) expire();  // window entries leave with their last term
  ++frame_;
}

void DiffusePathCache::makeRoomFor(uint64_t key, double invC) {
  if (entries_.size() == cap_.entries && indexFind(key) == cap_.indexSlots && !grow())
    makeRoom(invC);
}

void DiffusePathCache::seedEndFrame(const FrameGroups& frame, double invC, EnergyResponse& out,
                                    ArrivalSink* directional, double& total,
                                    double& coarse) {
  // Eq. 3.4, applied to the frame's hits of each path at once (the same sums).
  for (const FrameGroups::Group& g : frame.groups()) {
    makeRoomFor(g.key, invC);
    bool inserted = false;
    Entry* e = findOrInsert(g.key, inserted);
    if (inserted) {
      e->eta = float(g.eta);
      e->intensity = g.intensity;
      e->length = g.length;
      e->direction = g.direction;
    } else {
      e->eta += float(g.eta);
      e->intensity += g.intensity;
      e->length += g.length;
      e->direction += g.direction;
    }
  }
  // mu: rays emitted from the frame that created the entry (or layer) through this one.
  auto mu = [&](uint32_t stamp) {
    return float(raysTotal_ - raysBefore_[stamp % raysBefore_.size()]);
  };
  for (const Entry& e : entries_) {
    const double delay = meanDelaySeconds(e.length, e.eta, invC);  // eq. 3.3
    out.add(delay, e.intensity / mu(e.stamp));                     // eq. 3.2
    if (directional) directional->add(delay, e.intensity / mu(e.stamp), e.direction);
    total += double((e.intensity / mu(e.stamp)).average());
  }
  for (size_t l = 0; l < layers_; ++l)
    for (size_t b = 0; layerUsed_[l] && b < cap_.coarseBins; ++b)
      if (cell(l, b).eta > 0.f)
        readCell(cell(l, b), b, mu(layerStamp_[l]), invC, out, directional, coarse);
}

void DiffusePathCache::emaEndFrame(const FrameGroups& frame, float n, double invC,
                                   EnergyResponse& out, ArrivalSink* directional,
                                   double& total, double& coarse) {
  const float keep = float(1.0 - a_), af = float(a_);
  for (Entry& e : entries_) {
    e.intensity *= keep;
    e.length *= keep;
    e.eta *= keep;
    e.direction *= keep;
  }
  for (size_t b = 0; layerUsed_[0] && b < cap_.coarseBins; ++b) {
    Cell& c = cell(0, b);
    c.intensity *= keep;
    c.length *= keep;
    c.eta *= keep;
    c.direction *= keep;
  }
  for (const FrameGroups::Group& g : frame.groups()) {
    makeRoomFor(g.key, invC);
    bool inserted = false;
    Entry* e = findOrInsert(g.key, inserted);
    e->intensity += (g.intensity / n) * af;
    e->length += g.length * af;
    e->eta += float(g.eta) * af;
    e->direction += g.direction * af;
    e->stamp = frame_;
  }
  decayPow_ *= 1.0 - a_;
  const float norm = float(1.0 - decayPow_);
  readEntries(norm, invC, out, directional, total);
  for (size_t b = 0; layerUsed_[0] && b < cap_.coarseBins; ++b)
    if (cell(0, b).eta > 0.f) readCell(cell(0, b), b, norm, invC, out, directional, coarse);
}

void DiffusePathCache::expire() {
  for (size_t i = entries_.size(); i-- > 0;)
    if (frame_ - entries_[i].stamp + 1 >= lifetime_) removeAt(i);
  if (weighting_ == DpcWeighting::kSeed) {
    // The layer created L - 1 frames ago has been read out L times.
    const uint32_t l = (frame_ + 1) % lifetime_;
    if (frame_ + 1 >= lifetime_ && layerStamp_[l] + lifetime_ <= frame_ + 1 && layerUsed_[l]) {
      std::fill(&cell(l, 0), &cell(l, 0) + cap_.coarseBins, Cell{});
      layerUsed_[l] = 0;
    }
    return;
  }
  if (!layerUsed_[0]) return;
  size_t live = 0;
  for (size_t b = 0; b < cap_.coarseBins; ++b) {
    if (!(cell(0, b).eta > 0.f)) continue;
    if (frame_ - cell(0, b).stamp + 1 >= lifetime_)
      cell(0, b) = Cell{};
    else
      ++live;
  }
  layerUsed_[0] = live > 0;
}

}  // namespace dpc
