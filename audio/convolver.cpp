// Uniformly partitioned overlap-save convolution; see convolver.h for the algorithm and
// sources (Wefers 2015, section 5.3; Stockham 1966; Kulp 1988).
#include "audio/convolver.h"

#include <fftw3.h>

#include <algorithm>
#include <cassert>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>

#include "common/fftw_util.h"
#include "common/fftw_wisdom.h"

namespace dpc::audio {

namespace detail {
void FftwFree::operator()(float* p) const noexcept {
  fftwf_free(p);
}
}  // namespace detail

namespace detail {
FftwBuffer allocZeroed(size_t n) {
  float* p = fftwf_alloc_real(n);
  if (!p) throw std::bad_alloc();
  if (reinterpret_cast<uintptr_t>(p) % 16 != 0) {  // multiplyAccumulate's Float4 loads
    fftwf_free(p);
    throw std::runtime_error("fftwf_alloc_real returned memory not aligned to 16 bytes");
  }
  std::memset(p, 0, n * sizeof(float));
  return FftwBuffer(p);
}
}  // namespace detail

namespace {
using detail::allocZeroed;

constexpr size_t kLanes = 16;  ///< binStride multiple: 64 bytes, any SIMD width up to AVX-512

/// Sixteen floats (64 bytes, kLanes): one AVX-512 register, two AVX or four SSE registers,
/// whichever the clone below is compiled for. GCC/Clang vector extension: the -O2 default of
/// GCC 12 does not vectorise the plain loop (its "very cheap" cost model), so the vector code
/// is written out. Loaded and stored unaligned: the buffers guarantee 16 bytes, not 64.
typedef float Float16 __attribute__((vector_size(64)));
static_assert(kLanes == 16 && sizeof(Float16) == kLanes * sizeof(float));

}  // namespace

namespace detail {
// One clone per instruction set, chosen once when the library is loaded (GNU ifunc): the
// baseline x86-64 build would otherwise use 4-wide SSE only. No fused multiply-add (the build
// is ISO C++, -ffp-contract=off), so every clone computes the same float operations and the
// output is bit-identical on any machine. Not in sanitizer builds, whose runtimes are not yet
// set up when load-time resolvers run.
#if defined(__x86_64__) && !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#if !defined(__has_feature)
#define DPC_MAC_CLONES 1
#elif !__has_feature(address_sanitizer) && !__has_feature(thread_sanitizer)
#define DPC_MAC_CLONES 1
#endif
#endif
/// acc[k..k+16) += x * h for one lane group, x already loaded. Inlined into each clone below,
/// so it is compiled for that clone's instruction set.
__attribute__((always_inline)) inline void macLanes(float* __restrict accRe,
                                                    float* __restrict accIm, const Float16& xr,
                                                    const Float16& xi, const float* __restrict hRe,
                                                    const float* __restrict hIm, size_t k) {
  Float16 hr, hi, ar, ai;
  __builtin_memcpy(&hr, hRe + k, sizeof hr);
  __builtin_memcpy(&hi, hIm + k, sizeof hi);
  __builtin_memcpy(&ar, accRe + k, sizeof ar);
  __builtin_memcpy(&ai, accIm + k, sizeof ai);
  ar += xr * hr - xi * hi;
  ai += xr * hi + xi * hr;
  __builtin_memcpy(accRe + k, &ar, sizeof ar);
  __builtin_memcpy(accIm + k, &ai, sizeof ai);
}

#ifdef DPC_MAC_CLONES
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
void multiplyAccumulate(float* __restrict accRe, float* __restrict accIm,
                        const float* __restrict xRe, const float* __restrict xIm,
                        const float* __restrict hRe, const float* __restrict hIm, size_t n) {
  for (size_t k = 0; k < n; k += kLanes) {
    Float16 xr, xi;
    __builtin_memcpy(&xr, xRe + k, sizeof xr);
    __builtin_memcpy(&xi, xIm + k, sizeof xi);
    macLanes(accRe, accIm, xr, xi, hRe, hIm, k);
  }
}

#ifdef DPC_MAC_CLONES
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
void multiplyAccumulate2(float* __restrict acc0Re, float* __restrict acc0Im,
                         float* __restrict acc1Re, float* __restrict acc1Im,
                         const float* __restrict xRe, const float* __restrict xIm,
                         const float* __restrict h0Re, const float* __restrict h0Im,
                         const float* __restrict h1Re, const float* __restrict h1Im, size_t n) {
  for (size_t k = 0; k < n; k += kLanes) {
    Float16 xr, xi;
    __builtin_memcpy(&xr, xRe + k, sizeof xr);
    __builtin_memcpy(&xi, xIm + k, sizeof xi);
    macLanes(acc0Re, acc0Im, xr, xi, h0Re, h0Im, k);
    macLanes(acc1Re, acc1Im, xr, xi, h1Re, h1Im, k);
  }
}
}  // namespace detail

// ---------------------------------------------------------------------------------------------
// ConvolverLayout

ConvolverLayout::ConvolverLayout(int blockSize, size_t maxIrSamples, Planning planning)
    : blockSize_(blockSize) {
  if (blockSize <= 0)
    throw std::invalid_argument("ConvolverLayout: blockSize " + std::to_string(blockSize) +
                                " must be positive");
  if (maxIrSamples == 0)
    throw std::invalid_argument("ConvolverLayout: maxIrSamples must be positive");
  const size_t partitions = (maxIrSamples + size_t(blockSize) - 1) / size_t(blockSize);
  if (partitions > size_t(1) << 30 || blockSize > (1 << 29))
    throw std::invalid_argument("ConvolverLayout: sizes too large");
  numPartitions_ = int(partitions);
  binStride_ = (size_t(blockSize) + 1 + kLanes - 1) / kLanes * kLanes;

  // Measured plans come from the wisdom of earlier runs when it holds them (instant), and
  // what a run measures is kept for the next (common/fftw_wisdom.h).
  std::lock_guard lock(fftwPlannerMutex());
  void *fwd = nullptr, *inv = nullptr;
  if (planning != Planning::kEstimate) importFftwWisdomOnce();
  bool measured =
      planning == Planning::kMeasureLater && makePlans(FFTW_MEASURE | FFTW_WISDOM_ONLY, fwd, inv);
  if (!measured) {
    measured = planning == Planning::kMeasure;
    if (!makePlans(measured ? FFTW_MEASURE : FFTW_ESTIMATE, fwd, inv))
      throw std::runtime_error("ConvolverLayout: FFTW could not plan a " +
                               std::to_string(2 * blockSize) + "-point split real transform");
    if (measured) exportFftwWisdom();
  }
  forwardPlan_.store(fwd, std::memory_order_release);
  inversePlan_.store(inv, std::memory_order_release);
  measured_.store(measured, std::memory_order_release);
}

bool ConvolverLayout::makePlans(unsigned flags, void*& fwd, void*& inv) const {
  const int n = 2 * blockSize_;
  detail::FftwBuffer time = allocZeroed(size_t(n));
  // Split spectrum: imaginary parts binStride_ after the real parts. FFTW's new-array execute
  // requires every later array pair to keep this separation (and the buffers' alignment).
  detail::FftwBuffer spectrum = allocZeroed(2 * binStride_);
  float* re = spectrum.get();
  float* im = re + binStride_;
  fftwf_iodim dim{n, 1, 1};
  fftwf_plan f = fftwf_plan_guru_split_dft_r2c(1, &dim, 0, nullptr, time.get(), re, im, flags);
  // c2r: input (re, im) is destroyed, which the convolver allows (it is scratch).
  fftwf_plan i = fftwf_plan_guru_split_dft_c2r(1, &dim, 0, nullptr, re, im, time.get(),
                                               flags | FFTW_DESTROY_INPUT);
  if (!f || !i) {
    if (f) fftwf_destroy_plan(f);
    if (i) fftwf_destroy_plan(i);
    return false;
  }
  fwd = f;
  inv = i;
  return true;
}

void ConvolverLayout::measurePlans() const {
  std::lock_guard lock(fftwPlannerMutex());
  if (measured_.load(std::memory_order_relaxed)) return;
  void *fwd = nullptr, *inv = nullptr;
  if (!makePlans(FFTW_MEASURE, fwd, inv))
    throw std::runtime_error("ConvolverLayout: FFTW could not measure a " +
                             std::to_string(2 * blockSize_) + "-point split real transform");
  exportFftwWisdom();
  replacedPlans_[0] = forwardPlan_.exchange(fwd, std::memory_order_acq_rel);
  replacedPlans_[1] = inversePlan_.exchange(inv, std::memory_order_acq_rel);
  measured_.store(true, std::memory_order_release);
}

ConvolverLayout::~ConvolverLayout() {
  std::lock_guard lock(fftwPlannerMutex());
  fftwf_destroy_plan(static_cast<fftwf_plan>(forwardPlan_.load()));
  fftwf_destroy_plan(static_cast<fftwf_plan>(inversePlan_.load()));
  for (void* p : replacedPlans_)
    if (p) fftwf_destroy_plan(static_cast<fftwf_plan>(p));
}

void ConvolverLayout::forward(const float* time, float* spectrum) const {
  // FFTW's r2c does not write its input for out-of-place transforms; the signature is not const.
  fftwf_execute_split_dft_r2c(static_cast<fftwf_plan>(forwardPlan_.load(std::memory_order_acquire)),
                              const_cast<float*>(time), spectrum, spectrum + binStride_);
}

void ConvolverLayout::inverse(float* spectrum, float* time) const {
  fftwf_execute_split_dft_c2r(static_cast<fftwf_plan>(inversePlan_.load(std::memory_order_acquire)),
                              spectrum, spectrum + binStride_, time);
}

// ---------------------------------------------------------------------------------------------
// IrSpectrum, IrSpectra

IrSpectrum::IrSpectrum(const ConvolverLayout& layout)
    : layout_(&layout),
      data_(allocZeroed(size_t(layout.numPartitions()) * layout.spectrumFloats())),
      time_(allocZeroed(size_t(layout.fftSize()))) {}

void IrSpectrum::prepare(const float* ir, size_t n) {
  if (n > layout_->maxIrSamples())
    throw std::invalid_argument("IrSpectrum::prepare: IR of " + std::to_string(n) +
                                " samples exceeds the capacity of " +
                                std::to_string(layout_->maxIrSamples()));
  const size_t b = size_t(layout_->blockSize());
  const size_t bins = size_t(layout_->numBins());
  const float scale = 1.0f / float(layout_->fftSize());  // folds the IFFT normalisation in
  const int active = int((n + b - 1) / b);
  float* time = time_.get();
  std::fill(time + b, time + 2 * b, 0.0f);  // second half: zero padding, stays zero
  for (int p = 0; p < active; ++p) {
    const size_t begin = size_t(p) * b;
    const size_t count = std::min(b, n - begin);
    std::copy(ir + begin, ir + begin + count, time);
    std::fill(time + count, time + b, 0.0f);
    float* re = data_.get() + size_t(p) * layout_->spectrumFloats();
    float* im = re + layout_->binStride();
    layout_->forward(time, re);
    for (size_t k = 0; k < bins; ++k) {
      re[k] *= scale;
      im[k] *= scale;
    }
  }
  activePartitions_ = active;  // partitions >= active keep stale data but are never read
}

IrSpectra::IrSpectra(const ConvolverLayout& layout, int numChannels) {
  if (numChannels <= 0)
    throw std::invalid_argument("IrSpectra: numChannels " + std::to_string(numChannels) +
                                " must be positive");
  channels_.reserve(size_t(numChannels));
  for (int c = 0; c < numChannels; ++c) channels_.emplace_back(layout);
}

void IrSpectra::prepare(const float* const* irs, size_t n) {
  if (n > layout().maxIrSamples())  // check first so that no channel changes on error
    throw std::invalid_argument("IrSpectra::prepare: IR of " + std::to_string(n) +
                                " samples exceeds the capacity of " +
                                std::to_string(layout().maxIrSamples()));
  for (size_t c = 0; c < channels_.size(); ++c) channels_[c].prepare(irs[c], n);
}

// ---------------------------------------------------------------------------------------------
// PartitionedConvolver

PartitionedConvolver::PartitionedConvolver(const ConvolverLayout& layout, int numOutputs)
    : layout_(&layout), numOutputs_(numOutputs) {
  if (numOutputs <= 0)
    throw std::invalid_argument("PartitionedConvolver: numOutputs " + std::to_string(numOutputs) +
                                " must be positive");
  input_ = allocZeroed(size_t(layout.fftSize()));
  fdl_ = allocZeroed(size_t(layout.numPartitions()) * layout.spectrumFloats());
  acc_ = allocZeroed(layout.spectrumFloats());
  time_[0] = allocZeroed(size_t(layout.fftSize()));
  time_[1] = allocZeroed(size_t(layout.fftSize()));
}

void PartitionedConvolver::retire(const IrSpectra* ir) {
  // Retire only what is neither current nor pending (the same spectra may be set twice).
  if (!ir || ir == current_ || (hasPending_ && ir == pending_)) return;
  const bool room = retired_.tryPush(ir);  // setNextIr() guarantees room
  assert(room);
  (void)room;
}

bool PartitionedConvolver::setNextIr(const IrSpectra* ir) {
  if (ir) {
    const ConvolverLayout& l = ir->layout();
    if (l.blockSize() != layout_->blockSize() || l.numPartitions() != layout_->numPartitions() ||
        ir->numChannels() != numOutputs_)
      return false;
  }
  // Room for the replaced pending IR (now) and the current one (at the swap).
  if (retired_.size() + 2 > retired_.capacity()) return false;
  const IrSpectra* replaced = hasPending_ ? pending_ : nullptr;
  const bool wasPending = hasPending_;
  pending_ = ir;
  hasPending_ = ir != current_;  // setting the current IR again cancels a pending change
  if (wasPending) retire(replaced);
  return true;
}

const IrSpectra* PartitionedConvolver::takeRetired() {
  const IrSpectra* ir = nullptr;
  return retired_.tryPop(ir) ? ir : nullptr;
}

void PartitionedConvolver::reset() {
  std::fill(input_.get(), input_.get() + layout_->fftSize(), 0.0f);
  std::fill(fdl_.get(), fdl_.get() + size_t(layout_->numPartitions()) * layout_->spectrumFloats(),
            0.0f);
  head_ = 0;
  heard_ = false;
}

const float* PartitionedConvolver::convolveChannel(const IrSpectrum& h, int which) {
  const size_t stride = layout_->binStride();
  const int numPartitions = layout_->numPartitions();
  float* accRe = acc_.get();
  float* accIm = accRe + stride;
  std::fill(accRe, accRe + 2 * stride, 0.0f);
  // Y = sum_p X_p H_p, X_p in FDL slot (head_ + p) mod P: two contiguous runs, no modulo inside.
  const int active = h.activePartitions();
  const int firstRun = std::min(active, numPartitions - head_);
  for (int p = 0; p < active; ++p) {
    const int slot = p < firstRun ? head_ + p : p - firstRun;
    const float* xRe = fdl_.get() + size_t(slot) * 2 * stride;
    detail::multiplyAccumulate(accRe, accIm, xRe, xRe + stride, h.re(p), h.im(p), stride);
  }
  float* time = time_[which].get();
  layout_->inverse(accRe, time);
  return time + layout_->blockSize();  // overlap-save: the last B samples are valid
}

void PartitionedConvolver::run(const float* in, float* const* out, bool add) {
  const int b = layout_->blockSize();
  const size_t ub = size_t(b);
  // Input history [previous | current], transformed into the newest FDL slot.
  float* input = input_.get();
  std::memcpy(input, input + ub, ub * sizeof(float));
  std::memcpy(input + ub, in, ub * sizeof(float));
  head_ = head_ == 0 ? layout_->numPartitions() - 1 : head_ - 1;
  layout_->forward(input, fdl_.get() + size_t(head_) * layout_->spectrumFloats());

  // The first IR over a silent history starts at once: the silence it would fade in from is
  // what the IR itself gives there, so a sound that begins in this block keeps its onset.
  if (hasPending_ && !current_ && !heard_) {
    current_ = pending_;
    hasPending_ = false;
    pending_ = nullptr;
  }
  if (!heard_) heard_ = std::any_of(in, in + ub, [](float v) { return v != 0.0f; });
  const IrSpectra* next = hasPending_ ? pending_ : current_;
  const bool crossfade = hasPending_;
  const float invB = 1.0f / float(b);
  for (int c = 0; c < numOutputs_; ++c) {
    float* y = out[c];
    const float* oldY = current_ ? convolveChannel(current_->channel(c), 0) : nullptr;
    if (!crossfade) {
      if (oldY) {
        if (add)
          for (size_t n = 0; n < ub; ++n) y[n] += oldY[n];
        else
          std::memcpy(y, oldY, ub * sizeof(float));
      } else if (!add) {
        std::fill(y, y + ub, 0.0f);
      }
      continue;
    }
    // Crossfade block: out[n] = (1 - w[n]) old[n] + w[n] new[n], w[n] = (n + 1) / B.
    const float* newY = next ? convolveChannel(next->channel(c), 1) : nullptr;
    for (size_t n = 0; n < ub; ++n) {
      const float w = float(n + 1) * invB;
      const float v = (oldY ? (1.0f - w) * oldY[n] : 0.0f) + (newY ? w * newY[n] : 0.0f);
      y[n] = add ? y[n] + v : v;
    }
  }
  if (crossfade) {
    const IrSpectra* old = current_;
    current_ = next;
    hasPending_ = false;
    pending_ = nullptr;
    retire(old);
  }
}

}  // namespace dpc::audio
