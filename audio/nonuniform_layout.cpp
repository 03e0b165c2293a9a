// Partition levels of the non-uniform convolver; see nonuniform_layout.h.
#include "audio/nonuniform_layout.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace dpc::audio {

namespace {
constexpr int kMaxBlock = 8192;
constexpr size_t kMaxIrSamples = size_t(1) << 27;
}  // namespace

NonUniformLayout::NonUniformLayout(int blockSize, size_t maxIrSamples, int maxPartition,
                                   ConvolverLayout::Planning planning, int overlap)
    : blockSize_(blockSize), maxIrSamples_(maxIrSamples) {
  if (overlap < 0 || overlap > kMaxOverlap)
    throw std::invalid_argument("NonUniformLayout: overlap " + std::to_string(overlap) +
                                " outside 0.." + std::to_string(kMaxOverlap));
  if (blockSize < 1 || blockSize > kMaxBlock)
    throw std::invalid_argument("NonUniformLayout: blockSize " + std::to_string(blockSize) +
                                " outside 1.." + std::to_string(kMaxBlock));
  if (maxIrSamples < 1 || maxIrSamples > kMaxIrSamples)
    throw std::invalid_argument("NonUniformLayout: maxIrSamples " + std::to_string(maxIrSamples) +
                                " outside 1.." + std::to_string(kMaxIrSamples));
  if (maxPartition < blockSize)
    throw std::invalid_argument("NonUniformLayout: maxPartition " + std::to_string(maxPartition) +
                                " is below the block size " + std::to_string(blockSize));
  int capPeriod = 1;  // largest power of two with capPeriod * B <= maxPartition
  while (size_t(capPeriod) * 2 * size_t(blockSize) <= size_t(maxPartition)) capPeriod *= 2;

  const size_t b = size_t(blockSize);
  size_t offset = 0;
  int period = 1;
  for (;;) {
    const size_t n = size_t(period) * b;
    const int nextPeriod = std::min(4 * period, capPeriod);
    const size_t nextOffset = 2 * size_t(nextPeriod) * b - 2 * b;
    int partitions, shared = 0;
    bool last = nextPeriod == period || maxIrSamples <= nextOffset;
    if (last) {
      partitions = int((maxIrSamples - offset + n - 1) / n);
    } else {
      // The zone shared with the next level lies within its first partition.
      shared = std::min(overlap, nextPeriod / period);
      partitions = int((nextOffset - offset) / n) + shared;
    }
    ffts_.push_back(std::make_unique<ConvolverLayout>(int(n), size_t(partitions) * n, planning));
    levels_.push_back(Level{int(n), partitions, shared, offset, period, ffts_.back().get()});
    if (last) break;
    offset = nextOffset;
    period = nextPeriod;
  }
}

bool NonUniformLayout::plansMeasured() const {
  for (const auto& fft : ffts_)
    if (!fft->plansMeasured()) return false;
  return true;
}

void NonUniformLayout::measurePlans() const {
  for (const auto& fft : ffts_) fft->measurePlans();
}

int NonUniformLayout::totalPartitions() const {
  int total = 0;
  for (const Level& l : levels_) total += l.numPartitions;
  return total;
}

float NonUniformLayout::share(int l, size_t t) const {
  const Level& lv = levels_[size_t(l)];
  const size_t end = lv.offset + size_t(lv.numPartitions) * size_t(lv.partitionSize);
  if (t < lv.offset || t >= end) return 0.0f;
  // Level l's falling share across the zone [o_{l+1}, o_{l+1} + K_l N_l) it shares with l+1.
  const auto falling = [this](int k, size_t at) {
    const Level& a = levels_[size_t(k)];
    const double zone = double(a.overlapPartitions) * double(a.partitionSize);
    return float(1.0 - (double(at - levels_[size_t(k) + 1].offset) + 0.5) / zone);
  };
  if (lv.overlapPartitions > 0 && t >= levels_[size_t(l) + 1].offset) return falling(l, t);
  if (l > 0) {
    const Level& prev = levels_[size_t(l) - 1];
    if (t < lv.offset + size_t(prev.overlapPartitions) * size_t(prev.partitionSize))
      return 1.0f - falling(l - 1, t);
  }
  return 1.0f;
}

}  // namespace dpc::audio
