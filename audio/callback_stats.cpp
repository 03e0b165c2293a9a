#include "audio/callback_stats.h"

#include <algorithm>
#include <bit>

namespace dpc::audio {

int CallbackStats::binOf(uint64_t ns) noexcept {
  // Values below 32 have their own bins; above, an octave [2^e, 2^(e+1)) (e >= 5) is split
  // into 16 bins by the 4 bits below the leading one.
  if (ns < 32) return int(ns);
  const int width = std::bit_width(ns);  // e + 1, >= 6
  const int shift = width - 5;           // >= 1
  const int top = int(ns >> shift);      // in [16, 32)
  const int bin = 32 + (shift - 1) * 16 + (top - 16);
  return std::min(bin, kBins - 1);
}

uint64_t CallbackStats::binUpperNs(int bin) noexcept {
  if (bin < 32) return uint64_t(bin);
  const int shift = (bin - 32) / 16 + 1;
  const uint64_t top = uint64_t(16 + (bin - 32) % 16);
  return ((top + 1) << shift) - 1;
}

void CallbackStats::record(uint64_t durationNs, bool xrun) noexcept {
  // Single writer (the audio thread): plain load/store would do for max; fetch_add keeps the
  // counters right even if two threads ever recorded.
  callbacks_.fetch_add(1, std::memory_order_relaxed);
  if (xrun) xruns_.fetch_add(1, std::memory_order_relaxed);
  lastNs_.store(durationNs, std::memory_order_relaxed);
  if (durationNs > maxNs_.load(std::memory_order_relaxed)) {
    maxNs_.store(durationNs, std::memory_order_relaxed);
  }
  histogram_[size_t(binOf(durationNs))].fetch_add(1, std::memory_order_relaxed);
}

CallbackStats::Snapshot CallbackStats::snapshot() const noexcept {
  Snapshot s;
  s.callbacks = callbacks_.load(std::memory_order_relaxed);
  s.xruns = xruns_.load(std::memory_order_relaxed);
  s.lastNs = lastNs_.load(std::memory_order_relaxed);
  s.maxNs = maxNs_.load(std::memory_order_relaxed);
  for (size_t i = 0; i < size_t(kBins); ++i) {
    s.histogram[i] = histogram_[i].load(std::memory_order_relaxed);
  }
  return s;
}

uint64_t CallbackStats::Snapshot::quantileNs(double q) const noexcept {
  uint64_t total = 0;
  for (uint64_t c : histogram) total += c;
  if (total == 0) return 0;
  q = std::clamp(q, 0.0, 1.0);
  // Smallest bin whose cumulative count reaches ceil(q * total) (at least 1).
  uint64_t rank = uint64_t(q * double(total));
  if (double(rank) < q * double(total)) ++rank;
  rank = std::max<uint64_t>(rank, 1);
  uint64_t cumulative = 0;
  for (int b = 0; b < kBins; ++b) {
    cumulative += histogram[size_t(b)];
    // The bin's upper edge, but never above the largest duration recorded.
    if (cumulative >= rank) return maxNs > 0 ? std::min(binUpperNs(b), maxNs) : binUpperNs(b);
  }
  return maxNs;
}

uint64_t CallbackStats::Snapshot::meanNs() const noexcept {
  double total = 0, sum = 0;
  for (int b = 0; b < kBins; ++b) {
    const double count = double(histogram[size_t(b)]);
    const uint64_t edge = maxNs > 0 ? std::min(binUpperNs(b), maxNs) : binUpperNs(b);
    total += count;
    sum += count * double(edge);
  }
  return total > 0 ? uint64_t(sum / total + 0.5) : 0;
}

CallbackStats::Snapshot CallbackStats::Snapshot::since(const Snapshot& earlier) const noexcept {
  Snapshot d;
  d.callbacks = callbacks - std::min(callbacks, earlier.callbacks);
  d.xruns = xruns - std::min(xruns, earlier.xruns);
  d.lastNs = lastNs;
  for (size_t i = 0; i < size_t(kBins); ++i) {
    d.histogram[i] = histogram[i] - std::min(histogram[i], earlier.histogram[i]);
    if (d.histogram[i] > 0) d.maxNs = binUpperNs(int(i));
  }
  return d;
}

CallbackStats::Snapshot CallbackStats::Snapshot::plus(const Snapshot& later) const noexcept {
  Snapshot d;
  d.callbacks = callbacks + later.callbacks;
  d.xruns = xruns + later.xruns;
  d.lastNs = later.lastNs;
  d.maxNs = std::max(maxNs, later.maxNs);
  for (size_t i = 0; i < size_t(kBins); ++i) d.histogram[i] = histogram[i] + later.histogram[i];
  return d;
}

}  // namespace dpc::audio
