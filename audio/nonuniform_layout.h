// The partition levels of a non-uniformly partitioned convolution (NonUniformConvolver,
// audio/nonuniform_convolver.h): partition sizes, IR offsets, the overlap between levels,
// and one set of FFT plans per level.
//
// Sources: W. G. Gardner, "Efficient convolution without input-output delay", JAES 43(3), 1995
// (a short head partition and longer tail partitions, each level delayed so that its longer
// FFT has time to complete); G. Garcia, "Optimal filter partition for efficient convolution
// with short input/output delay", AES 113th Convention 2002 (the choice of partition sizes);
// F. Wefers, "Partitioned convolution algorithms for real-time auralization", PhD thesis, RWTH
// Aachen 2015, ch. 5-6 (each level is a uniformly partitioned overlap-save convolver with its
// own frequency-domain delay line, FDL).
//
// Layout (NonUniformLayout): level 0 has partitions of the block size B at IR offset 0; level
// l has partitions of N_l = B * 4^l samples (capped at maxPartition) starting at IR offset
// o_l = 2 N_l - 2 B, so level l covers [o_l, o_{l+1}) with 2 (N_{l+1} - N_l) / N_l partitions
// (6 when the size quadruples), and K_l overlap partitions more (below); the last level
// covers the rest of the IR.
//
// Overlapping levels: level l (all but the last) reaches K_l = min(K, N_{l+1} / N_l) partitions
// past o_{l+1} (K = 2 by default), into the zone [o_{l+1}, o_{l+1} + Z_l), Z_l = K_l N_l,
// which level l+1 covers too. There the IR is shared: level l carries share w(t) = 1 - (t -
// o_{l+1} + 1/2) / Z_l of sample t, level l+1 the rest, so the levels still sum to the IR
// (share()). Why: the levels swap IRs at different times (nonuniform_convolver.h, "IR swap":
// level l+1 starts its crossfade up to about 2 N_{l+1} later than level l). With a hard boundary,
// an arrival whose delay crosses o_{l+1} between two sets (a source receding or approaching) leaves
// level l before level l+1 takes it (silent for that time) or is played by both (+6 dB). In the
// zone it moves from one level to the other in steps of its delay change d between sets: what the
// later level holds back is at most d / Z_l of its amplitude per set it lags behind (about 3
// m_{l+1} blocks at most, more with staggered swaps, which add (G - 1) m_{l+1}). The price is K_l
// more partitions per level. (dpc's own remedy; docs/live.md "Overlapping levels" has its
// measurements.)
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "audio/convolver.h"

namespace dpc::audio {

/// Partition sizes, offsets and FFT plans of a non-uniform partitioning (see the file comment).
/// Must outlive every NonUniformIrSet / NonUniformConvolver made from it. Not copyable.
class NonUniformLayout {
 public:
  /// Default cap on the partition size, samples: a 16384-point FFT per level chunk keeps the
  /// callback that runs it short, while an IR of seconds needs few partitions.
  static constexpr int kDefaultMaxPartition = 8192;
  /// Default K: partitions each level reaches into the next one's segment (see "Overlapping
  /// levels"). 2 keeps a receding or approaching arrival's level within S d / (2 N_l) of its
  /// own (d its delay change between sets, S the sets the later level lags behind) for 6 more
  /// partitions on a 3 s IR at B = 128 (40, not 34).
  static constexpr int kDefaultOverlap = 2;
  /// Largest K accepted.
  static constexpr int kMaxOverlap = 4;

  struct Level {
    int partitionSize;     ///< N_l samples (a multiple of the block size)
    int numPartitions;     ///< P_l, the overlap partitions included
    int overlapPartitions;  ///< K_l: the last K_l partitions lie in the next level's segment
    size_t offset;         ///< o_l: IR sample where the level's first partition starts
    int period;            ///< m_l = N_l / B: callbacks per chunk
    ConvolverLayout* fft;  ///< 2 N_l-point transforms, split spectra of N_l + 1 bins
  };

  /// blockSize B in 1..8192 samples; maxIrSamples in 1..2^27 (the longest IR any set of this
  /// layout holds); maxPartition >= blockSize caps N_l (rounded down to B times a power of 2);
  /// overlap K in 0..kMaxOverlap (0: levels meet at a hard boundary, see "Overlapping levels").
  /// Control thread. Allocates, creates FFTW plans. Throws std::invalid_argument naming the
  /// out-of-range argument, std::runtime_error if FFTW cannot plan.
  NonUniformLayout(int blockSize, size_t maxIrSamples, int maxPartition = kDefaultMaxPartition,
                   ConvolverLayout::Planning planning = ConvolverLayout::Planning::kEstimate,
                   int overlap = kDefaultOverlap);
  NonUniformLayout(const NonUniformLayout&) = delete;
  NonUniformLayout& operator=(const NonUniformLayout&) = delete;

  int blockSize() const { return blockSize_; }
  size_t maxIrSamples() const { return maxIrSamples_; }
  int numLevels() const { return int(levels_.size()); }
  const Level& level(int l) const { return levels_[size_t(l)]; }
  /// Total partitions over all levels.
  int totalPartitions() const;
  /// The share in [0, 1] of IR sample t (0-based) that level l carries: 1 inside its segment,
  /// falling linearly across the zone it shares with level l+1 and rising across the one it
  /// shares with level l-1, 0 outside. The levels' shares of any sample sum to 1 (in float,
  /// to rounding). Any thread; no allocation.
  float share(int level, size_t t) const;
  /// Every level's ConvolverLayout::plansMeasured() and measurePlans() (same rules).
  bool plansMeasured() const;
  void measurePlans() const;

 private:
  int blockSize_;
  size_t maxIrSamples_;
  std::vector<Level> levels_;
  std::vector<std::unique_ptr<ConvolverLayout>> ffts_;
};

}  // namespace dpc::audio
