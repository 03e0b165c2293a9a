#include "engine/path_cache_store.h"

#include <bit>
#include <cmath>

namespace dpc {

// ---------------------------------------------------------------------------------------
// PathIndex

size_t PathIndex::find(uint64_t key) const {
  const size_t mask = count_ - 1;
  for (size_t i = home(key);; i = (i + 1) & mask) {
    if (slots_[i].index1 == 0) return count_;
    if (slots_[i].key == key) return i;
  }
}

void PathIndex::insert(uint64_t key, uint32_t index) {
  const size_t mask = count_ - 1;
  size_t i = home(key);
  while (slots_[i].index1 != 0 && slots_[i].key != key) i = (i + 1) & mask;
  slots_[i] = {key, index + 1};
}

void PathIndex::erase(uint64_t key) {
  const size_t mask = count_ - 1;
  size_t i = find(key);
  if (i == count_) return;
  for (size_t j = (i + 1) & mask; slots_[j].index1 != 0; j = (j + 1) & mask) {
    const size_t h = home(slots_[j].key);
    // Move j back into the hole at i unless its home lies cyclically in (i, j].
    const bool stays = i <= j ? (i < h && h <= j) : (i < h || h <= j);
    if (stays) continue;
    slots_[i] = slots_[j];
    i = j;
  }
  slots_[i].index1 = 0;
}

// ---------------------------------------------------------------------------------------
// One frame, clearing, counts

void PathCacheStore::endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                              EnergyResponse& out, ArrivalSink* directional) {
  const float n = float(raysEmitted);
  const double invC = 1.0 / double(speedOfSound);
  raysBefore_[frame_ % raysBefore_.size()] = raysTotal_;
  raysTotal_ += raysEmitted;
  double total = 0.0, coarse = 0.0;  // band-average energy read out: all, from the coarse store
  applyFrame(frame, n, invC, out, directional, total, coarse);
  total += coarse;
  coarseFraction_ = total > 0.0 ? coarse / total : 0.0;
  ++frame_;
}

void PathCacheStore::clear() {
  clearEntries();
  std::fill(coarse_.get(), coarse_.get() + shape_.coarseLayers * cap_.coarseBins, CoarseCell{});
  coarseSub_ = std::bit_floor(cap_.coarseBins);
  coarseFraction_ = 0.0;
  frame_ = 0;
  raysTotal_ = 0;
  std::fill(raysBefore_.begin(), raysBefore_.end(), 0);
  std::fill(layerUsed_.begin(), layerUsed_.end(), 0);
}

size_t PathCacheStore::coarseEntryCount() const {
  size_t n = 0;
  for (size_t l = 0; l < shape_.coarseLayers; ++l)
    if (layerUsed_[l])
      for (size_t b = 0; b < cap_.coarseBins; ++b)
        n += coarse_[l * cap_.coarseBins + b].hits > 0.f;
  return n;
}

size_t PathCacheStore::bytesInUse() const {
  return cap_.bytes - (cap_.entries - entryCount()) * kPathEntryBytes - unusedTermBytes();
}

// ---------------------------------------------------------------------------------------
// The coarse store

size_t PathCacheStore::binOf(uint64_t fine, size_t sub) {
  if (fine < sub) return size_t(fine);
  const int k = std::bit_width(fine / sub) - 1;  // octave: fine in [sub 2^k, sub 2^(k+1))
  return sub * size_t(k) + size_t(fine >> k);
}

size_t PathCacheStore::coarseBin(double delaySeconds) {
  constexpr double kBin = PathCacheLimits::kCoarseBinSeconds;
  const uint64_t fine = uint64_t(std::min(std::max(0.0, delaySeconds / kBin), 1e15));
  while (binOf(fine, coarseSub_) >= cap_.coarseBins && coarseSub_ > 1) widenCoarse();
  // One bin per octave and still beyond: the last bin (only with a handful of bins).
  return std::min(binOf(fine, coarseSub_), cap_.coarseBins - 1);
}

void PathCacheStore::widenCoarse() {
  // Halving S: every new bin is the union of old bins (octave k of S is octave k + 1 of S / 2,
  // bins twice as wide), so cells only add up and no energy leaves the store. New indices are
  // never above old ones, so an ascending pass moves each cell once.
  const size_t nb = cap_.coarseBins, sub = coarseSub_ / 2;
  for (size_t b = 0; b < nb; ++b) {
    const size_t to = binOf(binStart(b, coarseSub_), sub);
    if (to == b) continue;
    for (size_t l = 0; l < shape_.coarseLayers; ++l) {
      const CoarseCell src = cell(l, b);
      cell(l, b) = CoarseCell{};
      CoarseCell& d = cell(l, to);
      d.intensity += src.intensity;
      d.length += src.length;
      d.hits += src.hits;
      d.direction += src.direction;
      d.lastHit = std::max(d.lastHit, src.lastHit);
    }
  }
  coarseSub_ = sub;
}

void PathCacheStore::clearLayer(size_t layer) {
  if (layerUsed_[layer]) std::fill(&cell(layer, 0), &cell(layer, 0) + cap_.coarseBins, CoarseCell{});
  layerUsed_[layer] = 0;
}

void PathCacheStore::readCell(const CoarseCell& c, size_t bin, float divisor, double invC,
                              EnergyResponse& out, ArrivalSink* directional,
                              double& energy) const {
  constexpr double kBin = PathCacheLimits::kCoarseBinSeconds;
  const Bands i = c.intensity / divisor;
  energy += double(i.average());
  const size_t first = binStart(bin, coarseSub_),
               widthSteps = binStart(bin + 1, coarseSub_) - first;
  if (widthSteps == 1) {  // 1 ms bins: at the hit-weighted mean delay
    const double delay = meanDelaySeconds(c.length, c.hits, invC);
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
  const double mean = meanDelaySeconds(c.length, c.hits, invC);
  const double end = double(out.binCount()) * out.binSeconds();
  const double width = double(widthSteps) * kBin;
  const double centre = (double(first) + 0.5 * double(widthSteps)) * kBin;
  const double slope = std::clamp(6.0 * (mean - centre) / width, -1.0, 1.0);
  size_t steps = widthSteps;
  if (mean < end) steps = std::clamp<size_t>(size_t(std::ceil(end / kBin - 1e-6)) - first, 1, steps);
  auto weight = [&](size_t k) {
    const double t = (double(first + k) + 0.5) * kBin;
    return 1.0 + slope * (t - centre) / (0.5 * width);
  };
  double sum = 0.0;
  for (size_t k = 0; k < steps; ++k) sum += weight(k);
  for (size_t k = 0; k < steps; ++k) {
    const double delay = (double(first + k) + 0.5) * kBin;
    const Bands part = i * float(weight(k) / sum);
    out.add(delay, part);
    if (directional) directional->add(delay, part, c.direction);
  }
}

}  // namespace dpc
