// Uniformly partitioned overlap-save convolution (UPOLS) with a one-block crossfade on IR
// change.
//
// Algorithm: F. Wefers, "Partitioned convolution algorithms for real-time auralization", PhD
// thesis, RWTH Aachen 2015, section 5.3 (UPOLS); after T. G. Stockham, "High-speed convolution
// and correlation", AFIPS 1966, and R. Kulp, "Digital equalization using Fourier transform
// techniques", AES 85th Convention 1988. With block size B the IR h of length L is cut into
// P = ceil(L / B) partitions h_p[n] = h[pB + n], 0 <= n < B, each zero-padded to 2B and
// transformed: H_p = FFT_2B(h_p). Every block, the last 2B input samples [x_prev | x_cur] are
// transformed into X_0 and pushed onto a frequency-domain delay line (FDL) X_0..X_{P-1}
// (X_p is the spectrum from p blocks ago). Then Y = sum_p X_p H_p, y = IFFT_2B(Y), and the
// last B samples of y are the output block (the first B are circularly aliased and dropped:
// overlap-save). Latency: none beyond the block (output block k depends on input up to block k).
//
// Spectra are stored split: per partition, B + 1 real parts then B + 1 imaginary parts, each
// padded to binStride() (a multiple of 16 floats), so every array is SIMD aligned for FFTW's
// new-array execute functions, the imaginary parts sit at the fixed offset from the real parts
// that FFTW's split new-array execute requires, and the multiply-accumulate loop vectorises
// without a scalar tail.
//
// Threads: FFTW plan creation and destruction are not thread-safe, so ConvolverLayout is
// created and destroyed on the control/propagation thread (a mutex in convolver.cpp serialises
// only this file's planner calls, not other FFTW users such as IrSynthesizer). Executing plans
// on distinct arrays is thread-safe, so IrSpectrum::prepare (propagation thread) and
// PartitionedConvolver::process (audio thread) may run concurrently on one layout.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <vector>

#include "common/fixed_ring.h"

namespace dpc::audio {

namespace detail {
struct FftwFree {
  void operator()(float* p) const noexcept;
};
/// Float buffer from fftwf_alloc_real (SIMD aligned), freed with fftwf_free.
using FftwBuffer = std::unique_ptr<float[], FftwFree>;
/// n zeroed floats from fftwf_alloc_real. Allocates; throws std::bad_alloc, or
/// std::runtime_error if the memory is not 16-byte aligned.
FftwBuffer allocZeroed(size_t n);
/// acc += x * h over n complex bins in split format (real parts, imaginary parts). n is a
/// multiple of 16 and every pointer 16-byte aligned (ConvolverLayout::binStride() keeps both).
/// Any thread; no allocation.
void multiplyAccumulate(float* __restrict accRe, float* __restrict accIm,
                        const float* __restrict xRe, const float* __restrict xIm,
                        const float* __restrict hRe, const float* __restrict hIm, size_t n);
/// The same for two outputs from one input: acc0 += x * h0 and acc1 += x * h1, each bin's
/// float operations those of two multiplyAccumulate calls (bit-identical), x loaded once (a
/// stereo or binaural IR). Same layout rules; any thread; no allocation.
void multiplyAccumulate2(float* __restrict acc0Re, float* __restrict acc0Im,
                         float* __restrict acc1Re, float* __restrict acc1Im,
                         const float* __restrict xRe, const float* __restrict xIm,
                         const float* __restrict h0Re, const float* __restrict h0Im,
                         const float* __restrict h1Re, const float* __restrict h1Im, size_t n);
}  // namespace detail

/// Block size, FFT size (2B) and partition count shared by IR spectra and convolvers, and the
/// FFTW plans (real-to-complex and complex-to-real, split format, 2B points) they execute.
/// Must outlive every IrSpectrum/IrSpectra/PartitionedConvolver made from it. Not copyable or
/// movable (others keep a pointer to it).
class ConvolverLayout {
 public:
  enum class Planning {
    /// FFTW_ESTIMATE: instant, no trial runs. Default: FFTW_MEASURE takes seconds per size
    /// (too slow for tests and for re-layout at run time).
    kEstimate,
    /// FFTW_MEASURE: times candidate algorithms once (slow to create; for long-lived layouts,
    /// benchmarks).
    kMeasure,
    /// FFTW_MEASURE plans when the wisdom of earlier runs holds them (common/fftw_wisdom.h:
    /// made at once), else FFTW_ESTIMATE plans now and the measured ones by measurePlans()
    /// later (a live session's first sound need not wait for the planner).
    kMeasureLater,
  };

  /// blockSize B > 0 samples (any integer, not only powers of two); maxIrSamples > 0, the
  /// longest IR any spectrum of this layout can hold (P = ceil(maxIrSamples / B) partitions).
  /// Control/propagation thread (creates FFTW plans). Allocates. Throws std::invalid_argument
  /// on non-positive sizes, std::runtime_error if FFTW cannot create a plan or its allocator
  /// returns memory not aligned to 16 bytes.
  ConvolverLayout(int blockSize, size_t maxIrSamples, Planning planning = Planning::kEstimate);
  /// Control/propagation thread (destroys FFTW plans).
  ~ConvolverLayout();

  /// Whether forward() and inverse() run measured plans (kMeasure, or kMeasureLater once
  /// measured or made from wisdom). Any thread; no allocation.
  bool plansMeasured() const { return measured_.load(std::memory_order_acquire); }
  /// kMeasureLater: makes the measured plans (seconds, holding fftwPlannerMutex()), keeps them
  /// as wisdom and swaps them in: forward() and inverse() calls that start after it run them
  /// (the same transforms but for float rounding). The plans they replace live until the
  /// layout is destroyed (a thread may still be executing them). Nothing when measured
  /// already. Any thread but the audio thread; allocates; throws std::runtime_error when FFTW
  /// cannot plan (the estimated plans stay).
  void measurePlans() const;
  ConvolverLayout(const ConvolverLayout&) = delete;
  ConvolverLayout& operator=(const ConvolverLayout&) = delete;

  int blockSize() const { return blockSize_; }
  int fftSize() const { return 2 * blockSize_; }
  /// Complex bins per partition: B + 1.
  int numBins() const { return blockSize_ + 1; }
  /// Offset in floats from a split spectrum's real parts to its imaginary parts: B + 1 rounded
  /// up to a multiple of 16 (64 bytes, so offsets by it keep FFTW's SIMD alignment).
  size_t binStride() const { return binStride_; }
  int numPartitions() const { return numPartitions_; }
  /// numPartitions() * blockSize() (>= the maxIrSamples passed in).
  size_t maxIrSamples() const { return size_t(numPartitions_) * size_t(blockSize_); }

  /// Floats per split spectrum (one partition): 2 * binStride(), real parts at [0, B + 1),
  /// imaginary parts at [binStride(), binStride() + B + 1), zero padding in between.
  size_t spectrumFloats() const { return 2 * binStride_; }

  /// Forward transform of 2B real samples into one split spectrum (B + 1 bins, layout as in
  /// spectrumFloats()). Both arrays must be SIMD aligned (from fftwf_alloc_*, or offset by a
  /// multiple of binStride()); FFTW also requires the fixed real-to-imaginary separation,
  /// which the split layout guarantees. Any thread, thread-safe for distinct arrays; no
  /// allocation. Unnormalised (FFTW convention).
  void forward(const float* time, float* spectrum) const;
  /// Inverse transform of one split spectrum into 2B real samples; destroys the spectrum.
  /// Same rules as forward(). Unnormalised: inverse(forward(x)) = 2B x.
  void inverse(float* spectrum, float* time) const;

 private:
  int blockSize_;
  int numPartitions_;
  size_t binStride_;
  /// Makes the plans with FFTW `flags` (fftwPlannerMutex() held) into fwd and inv; false
  /// (nothing made) when FFTW returns none (FFTW_WISDOM_ONLY without wisdom for them).
  bool makePlans(unsigned flags, void*& fwd, void*& inv) const;
  /// The plans forward() and inverse() run (fftwf_plan), swapped once by measurePlans().
  mutable std::atomic<void*> forwardPlan_{nullptr}, inversePlan_{nullptr};
  /// kMeasureLater: the estimated plans measurePlans() replaced (destroyed with the layout).
  mutable void* replacedPlans_[2] = {nullptr, nullptr};
  mutable std::atomic<bool> measured_{false};
};

/// The partitioned spectrum of one IR channel: P partitions x (B + 1) complex bins, H_p scaled
/// by 1 / (2B) so the convolver needs no normalisation. Capacity is fixed at construction
/// (layout.maxIrSamples()); prepare() replaces the content without allocating. Move-only.
class IrSpectrum {
 public:
  /// Control/propagation thread. Allocates. Holds an empty (all-zero) IR until prepare().
  explicit IrSpectrum(const ConvolverLayout& layout);

  /// Partitions and transforms ir[0..n) (samples), zero-padding the last partition; an IR of
  /// n = 0 samples is silence. Propagation thread (any thread other than one processing a
  /// convolver that currently uses this spectrum). No allocation. Throws
  /// std::invalid_argument if n > layout.maxIrSamples() (the content is then unchanged).
  void prepare(const float* ir, size_t n);

  const ConvolverLayout& layout() const { return *layout_; }
  /// Partitions that hold the IR, ceil(n / B) of the last prepare(); the convolver skips the
  /// rest.
  int activePartitions() const { return activePartitions_; }
  /// Partition p's bins: real and imaginary parts, numBins() floats each.
  const float* re(int p) const { return data_.get() + size_t(p) * layout_->spectrumFloats(); }
  const float* im(int p) const { return re(p) + layout_->binStride(); }

 private:
  const ConvolverLayout* layout_;
  detail::FftwBuffer data_;  ///< P split spectra, P * spectrumFloats() floats
  detail::FftwBuffer time_;  ///< scratch, 2B floats
  int activePartitions_ = 0;
};

/// One IrSpectrum per output channel (mono 1, stereo/binaural 2): the unit a convolver swaps
/// in at once, so all channels change IR on the same block.
class IrSpectra {
 public:
  /// numChannels > 0. Control/propagation thread. Allocates. Throws std::invalid_argument if
  /// numChannels <= 0.
  IrSpectra(const ConvolverLayout& layout, int numChannels);

  /// irs[c][0..n) for each channel c < numChannels(); see IrSpectrum::prepare (same thread
  /// rules, no allocation, throws std::invalid_argument if n > layout.maxIrSamples()).
  void prepare(const float* const* irs, size_t n);

  int numChannels() const { return int(channels_.size()); }
  const ConvolverLayout& layout() const { return channels_[0].layout(); }
  IrSpectrum& channel(int c) { return channels_[size_t(c)]; }
  const IrSpectrum& channel(int c) const { return channels_[size_t(c)]; }

 private:
  std::vector<IrSpectrum> channels_;
};

/// Convolves one input signal with a numOutputs-channel IR (IrSpectra), all outputs sharing
/// one frequency-domain delay line of input spectra. IRs are borrowed, never owned or freed:
/// they are handed in with setNextIr() and handed back with takeRetired(). On an IR change the
/// next block is computed with both the old and the new IR from the same delay line (so both
/// are full, steady-state convolutions of the whole input history) and crossfaded linearly:
///   out[n] = (1 - w[n]) old[n] + w[n] new[n],  w[n] = (n + 1) / B,  0 <= n < B,
/// so the last sample of the block is purely new and every following block uses the new IR
/// alone. "No IR" (initially, or after setNextIr(nullptr)) is silence, so the first IR fades
/// in from silence and setNextIr(nullptr) fades out to silence; but an IR that replaces no IR
/// while every input so far was zero (since construction or reset(): an offline render's
/// first IR, set before its first block) starts at once, without the fade, as if it had
/// always been there, so a sound that begins in that block keeps its onset.
///
/// Threads: setNextIr(), process(), processAdd() and takeRetired() are called by one thread,
/// the audio thread, and are wait-free (no atomics needed: the hand-over between threads is
/// the owner's SPSC queues, docs/design.md "Audio side"). The audio thread should drain
/// takeRetired() into the return queue after each block.
class PartitionedConvolver {
 public:
  /// Retired spectra held until takeRetired(); setNextIr() refuses new IRs rather than
  /// overflow it.
  static constexpr int kRetiredCapacity = 8;

  /// numOutputs > 0 output channels. Control/propagation thread. Allocates (all the memory it
  /// will ever use). Throws std::invalid_argument if numOutputs <= 0.
  PartitionedConvolver(const ConvolverLayout& layout, int numOutputs);

  /// Schedules ir (or nullptr: silence) to replace the current IR, crossfading during the
  /// next process()/processAdd() block. If an IR is already pending it is replaced and
  /// retired (returned by takeRetired()), so the newest always wins. Returns false and
  /// changes nothing (the caller keeps ir) if ir is non-null and does not fit (different
  /// block size or partition count from this convolver's layout, or numChannels() !=
  /// numOutputs()), or if the retired list has fewer than 2 free slots (only possible when
  /// takeRetired() is not drained). Audio thread. Wait-free, no allocation, no exceptions.
  /// ir must stay alive and unmodified until it comes back from takeRetired().
  bool setNextIr(const IrSpectra* ir);

  /// Convolves exactly B samples in[0..B) and writes B samples to each out[c][0..B),
  /// c < numOutputs() (with no IR: zeros). in and the out[c] must not overlap each other. Audio
  /// thread. Wait-free: no allocation, locks, logging, exceptions or system calls.
  void process(const float* in, float* const* out) { run(in, out, false); }
  /// As process(), but adds into out[c][0..B) (mixing several sources into one bus).
  void processAdd(const float* in, float* const* out) { run(in, out, true); }

  /// One spectrum no longer used by this convolver (replaced while pending, or swapped out
  /// after its crossfade), oldest first; nullptr when none. Audio thread. Wait-free.
  const IrSpectra* takeRetired();

  /// The IR in use (nullptr: silence) and the one pending for the next block (valid only if
  /// hasPending()). For owners accounting for borrowed spectra, e.g. before destruction.
  const IrSpectra* currentIr() const { return current_; }
  const IrSpectra* pendingIr() const { return pending_; }
  bool hasPending() const { return hasPending_; }

  /// Clears the delay line and overlap (input history) to silence (the next IR to replace no
  /// IR starts at once again, above); IRs (current, pending) and retired list are kept. Not the
  /// audio thread (unless the audio thread itself calls it between blocks: it does not allocate).
  /// No errors.
  void reset();

  const ConvolverLayout& layout() const { return *layout_; }
  int numOutputs() const { return numOutputs_; }
  int blockSize() const { return layout_->blockSize(); }

 private:
  void run(const float* in, float* const* out, bool add);
  /// y = last B samples of IFFT(sum_p X_p H_p) for channel spectrum h, into time_[which].
  const float* convolveChannel(const IrSpectrum& h, int which);
  void retire(const IrSpectra* ir);

  const ConvolverLayout* layout_;
  int numOutputs_;
  detail::FftwBuffer input_;    ///< 2B floats: [previous block | current block]
  detail::FftwBuffer fdl_;      ///< ring of P split input spectra, P * spectrumFloats()
  detail::FftwBuffer acc_;      ///< one split spectrum: MAC accumulator
  detail::FftwBuffer time_[2];  ///< 2B floats each: IFFT outputs (old IR, new IR)
  int head_ = 0;                ///< FDL slot of X_0 (newest); X_p at (head_ + p) % P
  const IrSpectra* current_ = nullptr;
  const IrSpectra* pending_ = nullptr;
  bool hasPending_ = false;
  bool heard_ = false;  ///< a non-zero input sample since construction or reset()
  FixedRing<const IrSpectra*> retired_{kRetiredCapacity};
};

}  // namespace dpc::audio
