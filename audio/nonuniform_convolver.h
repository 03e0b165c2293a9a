// Non-uniformly partitioned overlap-save convolution (NUPOLS) of many sources into a shared
// output bus, with time-distributed work inside the audio callback and a click-free IR swap at
// every partition level.
//
// Sources: W. G. Gardner, "Efficient convolution without input-output delay", JAES 43(3), 1995
// (a short head partition and longer tail partitions, each level delayed so that its longer
// FFT has time to complete); G. Garcia, "Optimal filter partition for efficient convolution
// with short input/output delay", AES 113th Convention 2002 (the choice of partition sizes);
// F. Wefers, "Partitioned convolution algorithms for real-time auralization", PhD thesis, RWTH
// Aachen 2015, ch. 5-6 (each level is a uniformly partitioned overlap-save convolver with its
// own frequency-domain delay line, FDL).
//
// Layout (audio/nonuniform_layout.h): levels of partitions N_l = B 4^l from IR offsets
// o_l = 2 N_l - 2 B, each reaching K_l partitions into the next (a zone they share). Level
// l's work for one N_l-sample input chunk is spread over the m_l = N_l / B callbacks after the
// chunk is complete: the forward FFTs of the sources spread over the m callbacks (source s in
// callback s m / S), each followed by the spectral multiply-accumulate (MAC) of that source's
// partition 0; the MACs of partitions 1..P-1 (older input spectra) as (source, partition) pairs
// spread evenly over the same callbacks; the inverse FFTs in the last (callback m_l - 1), whose
// output chunk starts playing in that same callback. That is exactly when the IR offset o_l needs
// it, so the convolution adds no latency: output block k depends on input up to block k (as the
// uniform convolver, docs/live.md).
//
// Many sources: each source has its own FDL per level; sources are multiply-accumulated per
// output channel into one spectrum, so the inverse FFTs are one per output channel and level
// (two while that level crossfades), not one per source.
//
// Staggered levels: a level's heaviest callback is the last of its chunk (its inverse FFTs).
// Level l's chunks are offset by a phase of phi_l blocks (its chunk boundaries fall where
// block + phi_l is a multiple of m_l) so that the last callbacks of different levels, and of
// the levels of a second convolver in the same audio callback (phaseSlot 1: hybrid rendering's
// late buses beside the early parts), never coincide at the usual level counts: level 1
// finishes at blocks = slot (mod 4), level l >= 2 at a residue mod 16 that is 2 or 3 mod 4 and
// distinct per (level, slot) up to level 5 (kStaggeredLevels). The convolution is
// time-invariant in blocks, so a phase changes when a level's work happens, not its result:
// the input before the first block is zero, as the buffers start.
//
// Silent levels: a source whose IR sets in use (the current, the next and the newest) all
// start sounding at or after e_l + (e_l - o_l), e_l the end of level l's segment, skips level
// l's forward FFT: level l would multiply nothing for it (a distant source's direct sound is
// later than the short partitions reach), and the margin of one more segment lets the level
// transform the source again, and so refill its FDL, P_l chunks before an approaching
// source's response reaches the level. The FDL slots of skipped chunks are stale: a partition
// whose input chunk was skipped is not multiplied and is counted (stalePartitions()); that
// happens only when a response's onset moves earlier by more than a segment between two sets
// (a teleport, a direct sound coming out from behind an occluder). A set that is silent for
// the source, or no set, counts as sounding from 0: sound may follow silence anywhere. With no
// stale partition the output equals that of transforming every chunk.
//
// IR swap: the IR set is swapped for all sources at once. Each level takes the newest IR when
// it starts a chunk (the chunk's first callback above); if that differs from the IR of its
// previous chunk, the chunk is computed with both from the same FDL (both are steady-state
// convolutions of the whole input history) and crossfaded over the chunk's first block:
//   y_l[n] = (1 - g[n]) (x * h_old,l)[n] + g[n] (x * h_new,l)[n],  g[n] = min(1, (n + 1) / B),
// where h_l is the IR restricted to level l's segment, times the level's share
// (NonUniformLayout::share). One block, not the whole chunk: a moving source's arrival is at
// different delays in the two IRs, and their mix is a comb filter (for broadband sound 2/3 of
// the energy, -1.76 dB, averaged over a linear fade); over whole chunks a slow level of a
// moving source was never out of a fade. Level 0 thus swaps within one block,
// the tail levels at their own chunk boundaries (a later level's segment is later in the IR,
// so its swap is heard later anyway); an IR replaced before a level took it is skipped by
// that level. A level with no IR yet takes the first at once, without the crossfade, while
// every input so far was zero (an offline render's first IR, set before its first block): the
// silence it would fade in from is what the IR gives there, so a sound that begins in the
// first block keeps its onset.
//
// Staggered swaps (setSwapSpread): a level's swap may be spread over G_l chunks. The sources
// fall into G_l groups (source s in group s mod G_l: interleaved, because the chunk's work is
// spread over its callbacks in source order, and a contiguous group's doubled work would fall
// in one callback again); in chunk g of a swap, group g
// crossfades as above while the groups before it already use the new IR and those after it
// still the old one, so the swap's extra multiply-accumulates (both IRs of the crossfading
// sources) fall in G_l chunks instead of one. An IR that arrives during a staggered swap
// waits for its end (sets in between are skipped). G_l = clamp(spread / m_l, 1, S) for a
// spread of `spread` blocks; 1 block (the default) swaps every source in one chunk.
//
// Threads: NonUniformLayout and NonUniformIrSet construct on the control/propagation thread
// (FFTW plans and memory); NonUniformIrSet::prepare on the propagation thread;
// NonUniformConvolver::setNextIr/process/takeRetired on the audio thread only, wait-free: no
// allocation, locks, logging, exceptions or system calls.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "audio/convolver.h"
#include "audio/nonuniform_layout.h"

namespace dpc::audio {

/// The partitioned spectra of one IR set: numSources x numChannels IRs, each cut into the
/// layout's levels and partitions and transformed (scaled by 1 / (2 N_l): the convolver needs
/// no normalisation). Fixed capacity; prepare() replaces a source's IRs without allocating.
class NonUniformIrSet {
 public:
  /// numSources, numChannels, workers > 0. Control/propagation thread. Allocates (per worker
  /// a scratch of 2 x the largest partition floats). Throws std::invalid_argument on
  /// non-positive counts.
  NonUniformIrSet(const NonUniformLayout& layout, int numSources, int numChannels,
                  int workers = 1);

  /// Source s's IRs: irs[c][0..n) for every channel c (samples, pressure); n = 0 is silence.
  /// Propagation thread (or threads working for it: different sources concurrently, each
  /// with a worker index of its own in [0, workers)), while no convolver uses this set. No
  /// allocation. Throws std::invalid_argument if s or worker is out of range or
  /// n > layout.maxIrSamples() (nothing changed then).
  void prepare(int source, const float* const* irs, size_t n, int worker = 0);

  const NonUniformLayout& layout() const { return *layout_; }
  int numSources() const { return numSources_; }
  int numChannels() const { return numChannels_; }
  /// Worker indices prepare() accepts.
  int workers() const { return int(time_.size()); }
  /// Partitions of level l holding source s's IR (the rest are skipped).
  int activePartitions(int source, int level) const {
    return active_[size_t(source) * size_t(layout_->numLevels()) + size_t(level)];
  }
  /// The first partition of level l in which some channel of source s's IR is not silent
  /// (activePartitions when none is); the partitions before it are skipped.
  int firstSoundingPartition(int source, int level) const {
    return first_[size_t(source) * size_t(layout_->numLevels()) + size_t(level)];
  }
  /// Split spectrum of partition p of level l, source s, channel c.
  const float* spectrum(int level, int source, int channel, int p) const;
  /// The IR sample where source s's first sounding partition starts (over all levels);
  /// kSilent when every channel of its IR is silent.
  size_t onsetSample(int source) const { return onset_[size_t(source)]; }
  static constexpr size_t kSilent = SIZE_MAX;

 private:
  const NonUniformLayout* layout_;
  int numSources_, numChannels_;
  std::vector<detail::FftwBuffer> data_;  ///< per level: sources x channels x P_l spectra
  std::vector<int> active_;
  std::vector<int> first_;     ///< per source and level: firstSoundingPartition
  std::vector<size_t> onset_;  ///< per source: onsetSample
  std::vector<detail::FftwBuffer> time_;  ///< per worker: scratch, 2 N_max floats
};

/// numSources dry inputs convolved with a NonUniformIrSet and summed into numOutputs channels.
/// IR sets are borrowed: handed in by setNextIr(), handed back by takeRetired(). "No IR"
/// (initially, or setNextIr(nullptr)) is silence.
class NonUniformConvolver {
 public:
  /// Retired sets held until takeRetired().
  static constexpr int kRetiredCapacity = 32;

  /// Convolvers whose levels' last callbacks are kept apart (phaseSlot 0..kPhaseSlots-1).
  static constexpr int kPhaseSlots = 2;
  /// Levels 1..kStaggeredLevels never finish in the same callback as another of them (of
  /// either slot); deeper levels may.
  static constexpr int kStaggeredLevels = 5;

  /// phaseSlot in 0..kPhaseSlots-1: which of the convolvers run in one audio callback this is
  /// (see "Staggered levels"). Control thread. Allocates all the memory it will use. Throws
  /// std::invalid_argument on non-positive counts or a phase slot out of range.
  NonUniformConvolver(const NonUniformLayout& layout, int numSources, int numOutputs,
                      int phaseSlot = 0);

  /// Makes ir (or nullptr) the newest IR set; each level takes it at its next chunk (level 0:
  /// the next block). A set replaced before any level took it is retired. Returns false and
  /// changes nothing if ir does not match (layout, sources, channels) or the retired list is
  /// nearly full (takeRetired() not drained). Audio thread; wait-free.
  bool setNextIr(const NonUniformIrSet* ir);
  /// Whether setNextIr(ir) would succeed now. Audio thread; wait-free.
  bool canAccept(const NonUniformIrSet* ir) const;

  /// One block: in[s][0..B) per source, out[c][0..B) per output (written, or added to when
  /// add is true). Audio thread; wait-free, no allocation.
  void process(const float* const* in, float* const* out, bool add = false);

  /// A set no longer used by any level, oldest first; nullptr when none. Audio thread.
  const NonUniformIrSet* takeRetired();

  /// True while some level still uses an older set than the newest (a swap in progress).
  bool swapping() const;
  const NonUniformIrSet* newestIr() const { return target_; }
  /// phi_l: level l's chunks complete in the blocks k (counted from 0 at the first process())
  /// with k + phi_l = -1 (mod m_l), its last callback is k + phi_l = m_l - 2 (mod m_l).
  int levelPhase(int level) const { return levels_[size_t(level)].phase; }
  int numSources() const { return numSources_; }
  int numOutputs() const { return numOutputs_; }
  const NonUniformLayout& layout() const { return *layout_; }
  /// Whether levels a source is silent at skip its forward FFTs (see "Silent levels"; on by
  /// default). Off, every chunk is transformed and the output is exact whatever the onsets
  /// of successive sets. Control thread, before the first process().
  void setSkipSilentLevels(bool skip) { skipSilentLevels_ = skip; }
  /// Spreads each level's IR swap over at most `blocks` blocks (see "Staggered swaps"); a
  /// source group's new IR is heard up to blocks - 1 blocks after the set arrives. blocks >= 1.
  /// Control thread, before the first process(). Throws std::invalid_argument if blocks < 1.
  void setSwapSpread(int blocks);
  /// G_l: the source groups over whose chunks level l's swaps are spread.
  int swapGroups(int level) const { return levels_[size_t(level)].groups; }
  /// Blocks after a swap's first group until its last group crossfades: max over the levels of
  /// (G_l - 1) m_l (0 when no level is staggered, e.g. a single source).
  int swapDelayBlocks() const;
  /// Forward FFTs skipped so far because the source was silent at that level (see "Silent
  /// levels"). Any thread (relaxed).
  uint64_t skippedTransforms() const { return skippedTransforms_.load(std::memory_order_relaxed); }
  /// Partitions not multiplied because their input chunk was skipped (a response's onset
  /// jumped; see "Silent levels"): sound lost, counted once per partition, chunk and IR set
  /// multiplied (a crossfading level counts both sets). Any thread (relaxed).
  uint64_t stalePartitions() const { return stalePartitions_.load(std::memory_order_relaxed); }

 private:
  struct LevelState {
    /// Two windows per source, 2 N floats each, [previous chunk | chunk]: input[filling]
    /// receives the blocks of the chunk being filled, the other holds the complete chunk's
    /// window until its forward FFT.
    std::array<std::vector<detail::FftwBuffer>, 2> input;
    int filling = 0;
    std::vector<detail::FftwBuffer> fdl;  ///< per source: P spectra ring
    /// Per output: 3 spectra: the sources not crossfading (with whichever IR they use), and
    /// the crossfading sources' with the old IR and with the new.
    std::vector<detail::FftwBuffer> acc;
    std::vector<detail::FftwBuffer> out;  ///< per output: N samples being played
    detail::FftwBuffer time;              ///< 2 N floats: inverse FFT scratch (old, new)
    detail::FftwBuffer time2;
    int head = 0;                           ///< FDL slot of the newest chunk spectrum
    int phase = 0;                          ///< phi_l in 0..m_l-1 (see "Staggered levels")
    const NonUniformIrSet* cur = nullptr;   ///< IR of the previous chunk
    const NonUniformIrSet* next = nullptr;  ///< IR of the chunk being computed
    int groups = 1;                         ///< G_l (see "Staggered swaps")
    int swapGroup = 0;                      ///< the group crossfading while next != cur
    int64_t chunk = 0;                      ///< chunks started so far
    /// Per source: the last chunk whose forward FFT was skipped (see "Silent levels").
    std::vector<int64_t> skippedAt;
    /// A source whose IRs start sounding at or after this sample skips the level's FFTs.
    size_t needBefore = SIZE_MAX;
  };
  bool referenced(const NonUniformIrSet* ir) const;
  void retireIfUnused(const NonUniformIrSet* ir);
  /// One level's work in this callback: stage the input block, start, accumulate and finish
  /// the level's chunk as its schedule says, and add the level's output block.
  void processLevel(int level, const float* const* in, float* const* out);
  /// A chunk of the level's input is complete: switch input windows, take the newest IR.
  void startChunk(const NonUniformLayout::Level& lv, LevelState& st);
  /// Multiply-accumulates this callback's share of the level's partitions (both IRs while
  /// crossfading).
  void accumulateShare(int level, LevelState& st, int step, bool crossfade);
  /// Inverse transforms of the finished chunk, crossfaded over it when the IR changed.
  void finishChunk(const NonUniformLayout::Level& lv, LevelState& st, bool crossfade);
  /// Source s's partitions [begin, end) of ir (those it holds and whose input chunk was
  /// transformed) into acc (one per output). Returns the partitions left out as stale.
  int macSource(const LevelState& st, int level, const NonUniformIrSet* ir, float* const* acc,
                int s, int begin, int end) const;
  /// Whether source s's input must be transformed at this level in this chunk: some IR set
  /// in use sounds for it before the level's needBefore.
  bool inputNeeded(const LevelState& st, int s) const;
  /// macSource into the level's accumulators: steady (the IR the source's group uses), or
  /// both IRs while the source's group crossfades.
  void accumulate(int level, LevelState& st, int s, int begin, int end, bool crossfade);
  /// macSource of ir into accumulator `which` (0 steady, 1 old, 2 new); nothing for no IR.
  void accumulateInto(int level, LevelState& st, const NonUniformIrSet* ir, int which, int s,
                      int begin, int end);

  const NonUniformLayout* layout_;
  int numSources_, numOutputs_;
  std::vector<LevelState> levels_;
  std::vector<float*> accPtrs_;  ///< scratch: one accumulator pointer per output
  const NonUniformIrSet* target_ = nullptr;
  uint64_t block_ = 0;
  bool heard_ = false;  ///< a non-zero input sample in a block before this one
  bool skipSilentLevels_ = true;
  /// Written by the audio thread alone (load + store, no read-modify-write), read by any.
  std::atomic<uint64_t> skippedTransforms_{0};
  std::atomic<uint64_t> stalePartitions_{0};
  /// Adds n to a counter only the audio thread writes.
  static void count(std::atomic<uint64_t>& counter, uint64_t n) {
    if (n) counter.store(counter.load(std::memory_order_relaxed) + n, std::memory_order_relaxed);
  }
  FixedRing<const NonUniformIrSet*> retired_{kRetiredCapacity};
};

}  // namespace dpc::audio
