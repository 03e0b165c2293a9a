// Non-uniformly partitioned overlap-save convolution; see nonuniform_convolver.h for the
// algorithm and its sources (Gardner 1995, Garcia 2002, Wefers 2015 ch. 5-6).
#include "audio/nonuniform_convolver.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace dpc::audio {

using detail::allocZeroed;

NonUniformIrSet::NonUniformIrSet(const NonUniformLayout& layout, int numSources, int numChannels,
                                 int workers)
    : layout_(&layout), numSources_(numSources), numChannels_(numChannels) {
  if (numSources <= 0 || numChannels <= 0 || workers <= 0)
    throw std::invalid_argument("NonUniformIrSet: numSources " + std::to_string(numSources) +
                                ", numChannels " + std::to_string(numChannels) +
                                " and workers " + std::to_string(workers) + " must be positive");
  size_t maxN = 0;
  for (int l = 0; l < layout.numLevels(); ++l) {
    const NonUniformLayout::Level& lv = layout.level(l);
    data_.push_back(allocZeroed(size_t(numSources) * size_t(numChannels) *
                                size_t(lv.numPartitions) * lv.fft->spectrumFloats()));
    maxN = std::max(maxN, size_t(lv.partitionSize));
  }
  active_.assign(size_t(numSources) * size_t(layout.numLevels()), 0);
  first_.assign(active_.size(), 0);
  onset_.assign(size_t(numSources), kSilent);
  for (int w = 0; w < workers; ++w) time_.push_back(allocZeroed(2 * maxN));
}

const float* NonUniformIrSet::spectrum(int level, int source, int channel, int p) const {
  const NonUniformLayout::Level& lv = layout_->level(level);
  const size_t index =
      (size_t(source) * size_t(numChannels_) + size_t(channel)) * size_t(lv.numPartitions) +
      size_t(p);
  return data_[size_t(level)].get() + index * lv.fft->spectrumFloats();
}

namespace {
/// The first of level lv's `active` partitions in which some channel of irs (n samples each) is
/// not silent; `active` when all are.
int firstSounding(const NonUniformLayout::Level& lv, int active, const float* const* irs,
                  int numChannels, size_t n) {
  const size_t len = size_t(lv.partitionSize);
  for (int p = 0; p < active; ++p) {
    const size_t begin = lv.offset + size_t(p) * len, end = std::min(n, begin + len);
    for (int c = 0; c < numChannels; ++c)
      if (std::any_of(irs[c] + begin, irs[c] + end, [](float v) { return v != 0.0f; })) return p;
  }
  return active;
}
}  // namespace

namespace {
/// Scales the count samples of a partition of level l that starts at IR sample begin by the
/// level's share of each (NonUniformLayout::share); only where it is not 1.
void applyShare(const NonUniformLayout& layout, int l, size_t begin, size_t count, float* x) {
  const NonUniformLayout::Level& lv = layout.level(l);
  const bool sharedEnd = lv.overlapPartitions > 0 && begin + count > layout.level(l + 1).offset;
  const bool sharedStart = l > 0 && layout.level(l - 1).overlapPartitions > 0 &&
                           begin < lv.offset + size_t(layout.level(l - 1).overlapPartitions) *
                                                   size_t(layout.level(l - 1).partitionSize);
  if (!sharedEnd && !sharedStart) return;
  for (size_t k = 0; k < count; ++k) x[k] *= layout.share(l, begin + k);
}
}  // namespace

void NonUniformIrSet::prepare(int source, const float* const* irs, size_t n, int worker) {
  if (source < 0 || source >= numSources_)
    throw std::invalid_argument("NonUniformIrSet::prepare: source " + std::to_string(source) +
                                " outside 0.." + std::to_string(numSources_ - 1));
  if (n > layout_->maxIrSamples())
    throw std::invalid_argument("NonUniformIrSet::prepare: IR of " + std::to_string(n) +
                                " samples exceeds the layout's " +
                                std::to_string(layout_->maxIrSamples()));
  if (worker < 0 || size_t(worker) >= time_.size())
    throw std::invalid_argument("NonUniformIrSet::prepare: worker " + std::to_string(worker) +
                                " outside 0.." + std::to_string(time_.size() - 1));
  float* time = time_[size_t(worker)].get();
  for (int l = 0; l < layout_->numLevels(); ++l) {
    const NonUniformLayout::Level& lv = layout_->level(l);
    const size_t len = size_t(lv.partitionSize);
    const size_t bins = size_t(lv.fft->numBins());
    const float scale = 1.0f / float(lv.fft->fftSize());
    const size_t left = n > lv.offset ? n - lv.offset : 0;
    const int active = int(std::min<size_t>((left + len - 1) / len, size_t(lv.numPartitions)));
    for (int c = 0; c < numChannels_; ++c) {
      for (int p = 0; p < active; ++p) {
        const size_t begin = lv.offset + size_t(p) * len;
        const size_t count = std::min(len, n - begin);
        std::copy(irs[c] + begin, irs[c] + begin + count, time);
        std::fill(time + count, time + 2 * len, 0.0f);
        applyShare(*layout_, l, begin, count, time);
        float* re = const_cast<float*>(spectrum(l, source, c, p));
        float* im = re + lv.fft->binStride();
        lv.fft->forward(time, re);
        for (size_t k = 0; k < bins; ++k) {
          re[k] *= scale;
          im[k] *= scale;
        }
      }
    }
    const size_t at = size_t(source) * size_t(layout_->numLevels()) + size_t(l);
    active_[at] = active;
    first_[at] = firstSounding(lv, active, irs, numChannels_, n);
  }
  // The earliest first sounding partition over the levels (overlapping levels may both sound).
  onset_[size_t(source)] = kSilent;
  for (int l = 0; l < layout_->numLevels(); ++l) {
    const int first = firstSoundingPartition(source, l);
    if (first == activePartitions(source, l)) continue;
    const NonUniformLayout::Level& lv = layout_->level(l);
    onset_[size_t(source)] =
        std::min(onset_[size_t(source)], lv.offset + size_t(first) * size_t(lv.partitionSize));
  }
}

// ---------------------------------------------------------------------------------------------

namespace {
/// The block residue (mod m) in which level l >= 1 of phase slot `slot` does its last callback:
/// level 1 at slot (mod 4); level l >= 2 at 2 + (i mod 2) + 4 (i / 2 mod 4), i = 2 (l - 2) +
/// slot: residues 2, 3 mod 4 (never level 1's), distinct mod 16 up to level 5.
int finishingResidue(int level, int slot) {
  if (level == 1) return slot;
  const int i = 2 * (level - 2) + slot;
  return 2 + i % 2 + 4 * ((i / 2) % 4);
}
}  // namespace

NonUniformConvolver::NonUniformConvolver(const NonUniformLayout& layout, int numSources,
                                         int numOutputs, int phaseSlot)
    : layout_(&layout), numSources_(numSources), numOutputs_(numOutputs) {
  if (numSources <= 0 || numOutputs <= 0)
    throw std::invalid_argument("NonUniformConvolver: numSources " + std::to_string(numSources) +
                                " and numOutputs " + std::to_string(numOutputs) +
                                " must be positive");
  if (phaseSlot < 0 || phaseSlot >= kPhaseSlots)
    throw std::invalid_argument("NonUniformConvolver: phaseSlot " + std::to_string(phaseSlot) +
                                " outside 0.." + std::to_string(kPhaseSlots - 1));
  levels_.resize(size_t(layout.numLevels()));
  for (int l = 0; l < layout.numLevels(); ++l) {
    const NonUniformLayout::Level& lv = layout.level(l);
    LevelState& st = levels_[size_t(l)];
    // Last callback where block + phase = m - 2 (mod m), i.e. at block = residue (mod m).
    const int m = lv.period;
    if (l > 0 && m > 1) st.phase = ((m - 2 - finishingResidue(l, phaseSlot)) % m + m) % m;
    const size_t n = size_t(lv.partitionSize);
    const size_t spec = lv.fft->spectrumFloats();
    for (int s = 0; s < numSources; ++s) {
      for (auto& buffers : st.input) buffers.push_back(allocZeroed(2 * n));
      st.fdl.push_back(allocZeroed(size_t(lv.numPartitions) * spec));
    }
    for (int c = 0; c < numOutputs; ++c) {
      st.acc.push_back(allocZeroed(3 * spec));
      st.out.push_back(allocZeroed(n));
    }
    st.time = allocZeroed(2 * n);
    st.time2 = allocZeroed(2 * n);
    // Every slot of a new FDL holds the (zero) spectrum of the zero input before the start.
    st.skippedAt.assign(size_t(numSources), std::numeric_limits<int64_t>::min() / 2);
    if (l + 1 < layout.numLevels()) {
      const size_t end = lv.offset + size_t(lv.numPartitions) * n;
      st.needBefore = end + (end - lv.offset);
    }
  }
  accPtrs_.assign(size_t(numOutputs), nullptr);
}

bool NonUniformConvolver::referenced(const NonUniformIrSet* ir) const {
  if (ir == target_) return true;
  for (const LevelState& st : levels_)
    if (st.cur == ir || st.next == ir) return true;
  return false;
}

void NonUniformConvolver::retireIfUnused(const NonUniformIrSet* ir) {
  if (!ir || referenced(ir)) return;
  // setNextIr() keeps room for one per level and one more.
  const bool room = retired_.tryPush(ir);
  assert(room);
  (void)room;
}

bool NonUniformConvolver::canAccept(const NonUniformIrSet* ir) const {
  if (ir && (&ir->layout() != layout_ || ir->numSources() != numSources_ ||
             ir->numChannels() != numOutputs_))
    return false;
  return retired_.size() + size_t(layout_->numLevels()) + 1 <= retired_.capacity();
}

bool NonUniformConvolver::setNextIr(const NonUniformIrSet* ir) {
  if (!canAccept(ir)) return false;
  const NonUniformIrSet* old = target_;
  target_ = ir;
  if (old != ir) retireIfUnused(old);
  return true;
}

const NonUniformIrSet* NonUniformConvolver::takeRetired() {
  const NonUniformIrSet* ir = nullptr;
  return retired_.tryPop(ir) ? ir : nullptr;
}

bool NonUniformConvolver::swapping() const {
  for (const LevelState& st : levels_)
    if (st.cur != target_ || st.next != target_) return true;
  return false;
}

bool NonUniformConvolver::inputNeeded(const LevelState& st, int s) const {
  if (!skipSilentLevels_) return true;
  // No IR, or an IR silent for s, is not known to stay silent: the next set may sound at once.
  for (const NonUniformIrSet* ir : {st.cur, st.next, target_})
    if (!ir || ir->onsetSample(s) == NonUniformIrSet::kSilent || ir->onsetSample(s) < st.needBefore)
      return true;
  return false;
}

int NonUniformConvolver::macSource(const LevelState& st, int level, const NonUniformIrSet* ir,
                                   float* const* acc, int s, int begin, int end) const {
  const NonUniformLayout::Level& lv = layout_->level(level);
  const size_t stride = lv.fft->binStride();
  const size_t spec = lv.fft->spectrumFloats();
  const int numPartitions = lv.numPartitions;
  // Partitions before the first sounding one (a distant source's direct-sound delay) and after
  // the last add nothing; those from the first skipped input chunk on are stale.
  const int first = std::max(begin, ir->firstSoundingPartition(s, level));
  const int stop = std::min(end, ir->activePartitions(s, level));
  const int64_t fresh = st.chunk - st.skippedAt[size_t(s)];
  const int valid = int(std::min<int64_t>(stop, std::max<int64_t>(first, fresh)));
  const float* fdl = st.fdl[size_t(s)].get();
  for (int p = first; p < valid; ++p) {
    // X from p chunks ago sits in slot (head + p) mod P.
    int slot = st.head + p;
    if (slot >= numPartitions) slot -= numPartitions;
    const float* x = fdl + size_t(slot) * spec;
    if (numOutputs_ == 2) {  // stereo, binaural: x loaded once for both
      const float* h0 = ir->spectrum(level, s, 0, p);
      const float* h1 = ir->spectrum(level, s, 1, p);
      detail::multiplyAccumulate2(acc[0], acc[0] + stride, acc[1], acc[1] + stride, x, x + stride,
                                  h0, h0 + stride, h1, h1 + stride, stride);
      continue;
    }
    for (int c = 0; c < numOutputs_; ++c) {
      const float* h = ir->spectrum(level, s, c, p);
      detail::multiplyAccumulate(acc[c], acc[c] + stride, x, x + stride, h, h + stride, stride);
    }
  }
  return stop - valid;
}

void NonUniformConvolver::accumulateInto(int level, LevelState& st, const NonUniformIrSet* ir,
                                         int which, int s, int begin, int end) {
  if (!ir) return;
  const size_t spec = layout_->level(level).fft->spectrumFloats();
  for (int c = 0; c < numOutputs_; ++c)
    accPtrs_[size_t(c)] = st.acc[size_t(c)].get() + size_t(which) * spec;
  count(stalePartitions_, uint64_t(macSource(st, level, ir, accPtrs_.data(), s, begin, end)));
}

void NonUniformConvolver::accumulate(int level, LevelState& st, int s, int begin, int end,
                                     bool crossfade) {
  if (!crossfade) return accumulateInto(level, st, st.cur, 0, s, begin, end);
  const int group = s % st.groups;
  if (group != st.swapGroup)  // swapped already, or not yet
    return accumulateInto(level, st, group < st.swapGroup ? st.next : st.cur, 0, s, begin, end);
  accumulateInto(level, st, st.cur, 1, s, begin, end);
  accumulateInto(level, st, st.next, 2, s, begin, end);
}

void NonUniformConvolver::setSwapSpread(int blocks) {
  if (blocks < 1)
    throw std::invalid_argument("NonUniformConvolver::setSwapSpread: blocks " +
                                std::to_string(blocks) + " is below 1");
  for (int l = 0; l < layout_->numLevels(); ++l)
    levels_[size_t(l)].groups = std::clamp(blocks / layout_->level(l).period, 1, numSources_);
}

int NonUniformConvolver::swapDelayBlocks() const {
  int delay = 0;
  for (int l = 0; l < layout_->numLevels(); ++l)
    delay = std::max(delay, (levels_[size_t(l)].groups - 1) * layout_->level(l).period);
  return delay;
}

void NonUniformConvolver::process(const float* const* in, float* const* out, bool add) {
  const size_t ub = size_t(layout_->blockSize());
  if (!add)
    for (int c = 0; c < numOutputs_; ++c) std::fill(out[c], out[c] + ub, 0.0f);
  for (int l = 0; l < layout_->numLevels(); ++l) processLevel(l, in, out);
  for (int s = 0; s < numSources_ && !heard_; ++s)
    heard_ = std::any_of(in[s], in[s] + ub, [](float v) { return v != 0.0f; });
  ++block_;
}

void NonUniformConvolver::processLevel(int l, const float* const* in, float* const* out) {
  const NonUniformLayout::Level& lv = layout_->level(l);
  LevelState& st = levels_[size_t(l)];
  const int m = lv.period;
  const size_t ub = size_t(layout_->blockSize());
  const int inPos = int((block_ + uint64_t(st.phase)) % uint64_t(m));
  const int step = inPos + 1 == m ? 0 : inPos + 1;  // callback index within the chunk's work

  for (int s = 0; s < numSources_; ++s)
    std::memcpy(
        st.input[st.filling][size_t(s)].get() + size_t(lv.partitionSize) + size_t(inPos) * ub,
        in[s], ub * sizeof(float));
  if (step == 0) startChunk(lv, st);
  const bool crossfade = st.next != st.cur;
  // Sources whose forward FFT falls in this callback: s with s m / S == step. Each source's
  // newest partition (0) multiplies its spectrum as soon as it exists.
  const size_t n = size_t(lv.partitionSize);
  const int ready = 1 - st.filling;
  for (int s = int((int64_t(step) * numSources_ + m - 1) / m);
       s < numSources_ && int(int64_t(s) * m / numSources_) == step; ++s) {
    const float* window = st.input[size_t(ready)][size_t(s)].get();
    if (inputNeeded(st, s)) {
      lv.fft->forward(window, st.fdl[size_t(s)].get() + size_t(st.head) * lv.fft->spectrumFloats());
    } else {
      st.skippedAt[size_t(s)] = st.chunk;
      count(skippedTransforms_, 1);
    }
    // The chunk just transformed is the first half of the next chunk's window.
    std::memcpy(st.input[size_t(st.filling)][size_t(s)].get(), window + n, n * sizeof(float));
    accumulate(l, st, s, 0, 1, crossfade);
  }
  accumulateShare(l, st, step, crossfade);
  if (step == m - 1) finishChunk(lv, st, crossfade);

  // Play this callback's block of the chunk computed at step m - 1.
  const size_t at = size_t(step + 1 == m ? 0 : step + 1) * ub;
  for (int c = 0; c < numOutputs_; ++c) {
    const float* y = st.out[size_t(c)].get() + at;
    float* o = out[c];
    for (size_t k = 0; k < ub; ++k) o[k] += y[k];
  }
}

void NonUniformConvolver::startChunk(const NonUniformLayout::Level& lv, LevelState& st) {
  // A chunk is complete: its window (the previous chunk and this one) stays in its input
  // buffer while the next chunk fills the other one; the sources' forward FFTs spread over the
  // chunk's m callbacks (processLevel).
  st.filling = 1 - st.filling;
  ++st.chunk;
  st.head = st.head == 0 ? lv.numPartitions - 1 : st.head - 1;
  // The chunk's IR: the newest now, unless a staggered swap is still under way.
  if (st.next == st.cur) {
    st.next = target_;
    st.swapGroup = 0;
  }
  if (!st.cur && !heard_) st.cur = st.next;  // the first IR over a silent history: at once
  // The steady accumulator, and the crossfading group's two while a swap runs.
  const size_t used = (st.next != st.cur ? 3 : 1) * lv.fft->spectrumFloats();
  for (int c = 0; c < numOutputs_; ++c)
    std::fill(st.acc[size_t(c)].get(), st.acc[size_t(c)].get() + used, 0.0f);
}

void NonUniformConvolver::accumulateShare(int l, LevelState& st, int step, bool crossfade) {
  // This callback's share of the older partitions 1..P-1 (input already transformed): their
  // (source, partition) pairs spread evenly over the chunk's m callbacks, so that no callback
  // does a whole partition of every source (level 0: all of them, every callback).
  const NonUniformLayout::Level& lv = layout_->level(l);
  const int m = lv.period;
  const int older = lv.numPartitions - 1;
  const int64_t units = int64_t(numSources_) * older;
  const int64_t begin = units * step / m, end = units * (step + 1) / m;
  for (int64_t u = begin; u < end;) {
    const int s = int(u / older);
    const int p = 1 + int(u % older);
    const int stop = p + int(std::min<int64_t>(end - u, older - (p - 1)));
    accumulate(l, st, s, p, stop, crossfade);
    u += stop - p;
  }
}

void NonUniformConvolver::finishChunk(const NonUniformLayout::Level& lv, LevelState& st,
                                      bool crossfade) {
  // Inverse transforms: the chunk that starts playing in this callback (overlap-save: the last
  // N of 2N samples are valid). The steady sources' part is played as it is; the crossfading
  // group's, y = (1 - g) old + g new with g = (k + 1) / N over the chunk, is added to it.
  const size_t n = size_t(lv.partitionSize);
  const size_t spec = lv.fft->spectrumFloats();
  // While every source crossfades, no source is steady.
  const bool steady = crossfade ? st.groups > 1 : st.cur != nullptr;
  for (int c = 0; c < numOutputs_; ++c) {
    float* y = st.out[size_t(c)].get();
    float* acc = st.acc[size_t(c)].get();
    if (steady) {
      lv.fft->inverse(acc, st.time.get());
      std::memcpy(y, st.time.get() + n, n * sizeof(float));
    } else {
      std::fill(y, y + n, 0.0f);
    }
    if (!crossfade) continue;
    const float* oldY = nullptr;
    const float* newY = nullptr;
    if (st.cur) {
      lv.fft->inverse(acc + spec, st.time.get());
      oldY = st.time.get() + n;
    }
    if (st.next) {
      lv.fft->inverse(acc + 2 * spec, st.time2.get());
      newY = st.time2.get() + n;
    }
    // One block's ramp at every level (see "IR swap"), then the new IR alone.
    const size_t ramp = std::min(n, size_t(layout_->blockSize()));
    const float invRamp = 1.0f / float(ramp);
    for (size_t k = 0; k < n; ++k) {
      const float g = k < ramp ? float(k + 1) * invRamp : 1.0f;
      y[k] += (oldY ? (1.0f - g) * oldY[k] : 0.0f) + (newY ? g * newY[k] : 0.0f);
    }
  }
  if (crossfade && ++st.swapGroup == st.groups) {
    const NonUniformIrSet* old = st.cur;
    st.cur = st.next;
    retireIfUnused(old);
  }
}

}  // namespace dpc::audio
