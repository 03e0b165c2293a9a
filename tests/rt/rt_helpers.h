// Helpers shared by the real-time tests in tests/rt: the IR hand-over of docs/design.md
// "Audio side" (a pool of IR spectra passed from a main thread to an audio-role thread through
// one FixedRing and returned through another) and a cheap noise source. Used by the
// allocation-counting *_rt_test.cpp and by the ThreadSanitizer *_tsan_test.cpp, so nothing here
// depends on the allocation interposer (tests/rt/alloc_counter.*), which TSan builds leave out.
// Nothing here allocates after construction.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <thread>
#include <vector>

#include "common/fixed_ring.h"

namespace dpc::test {

/// Uniform noise in [-amplitude, amplitude) from a 32-bit LCG; advances `state`.
inline float lcgNoise(uint32_t& state, float amplitude) noexcept {
  state = state * 1664525u + 1013904223u;
  return float(int32_t(state)) * (amplitude / 2147483648.0f);
}

/// Sizes of a hand-over test and how long its audio thread runs.
struct HandOverSpec {
  int block;         ///< frames per audio block
  int channels;      ///< output channels
  size_t irSamples;  ///< longest IR
  int pool;          ///< IR spectra in the pool (and the capacity of either ring)
  uint64_t minBlocks;
  uint64_t minSwaps;

  /// When the audio thread gives up waiting for enough blocks and swaps (the main thread's pace
  /// varies, especially under TSan).
  static std::chrono::steady_clock::time_point deadline() {
    return std::chrono::steady_clock::now() + std::chrono::seconds(60);
  }
  /// Whether the audio thread renders another block: until both enough blocks and enough swaps
  /// happened, bounded by `deadline`.
  bool running(uint64_t blocks, uint64_t swaps,
               std::chrono::steady_clock::time_point deadline) const {
    return (blocks < minBlocks || swaps < minSwaps) && std::chrono::steady_clock::now() < deadline;
  }
};

/// What offerLatest did with the newest IR.
enum class Offer { nothing, taken, refused };

/// Audio thread: hands every IR `convolver` has finished with to giveBack(ir).
template <typename Convolver, typename GiveBack>
void returnRetired(Convolver& convolver, GiveBack&& giveBack) {
  while (const auto* spent = convolver.takeRetired()) giveBack(spent);
}

/// A pool of `Ir` (IrSpectra, NonUniformIrSet) and the two rings between the main thread, which
/// prepares free ones and sends them (toAudio), and the audio thread, which returns spent ones
/// (toMain). Both rings can hold the whole pool, so a push can only fail if a pointer were
/// duplicated.
template <typename Ir>
struct IrHandOver {
  std::vector<std::unique_ptr<Ir>> pool;
  std::vector<Ir*> freeList;  ///< main thread: not queued, not held by the convolver
  FixedRing<const Ir*> toAudio;
  FixedRing<const Ir*> toMain;

  /// `size` spectra, each constructed from `args`. Allocates.
  template <typename... Args>
  explicit IrHandOver(int size, const Args&... args) : toAudio(size_t(size)), toMain(size_t(size)) {
    for (int i = 0; i < size; ++i) {
      pool.push_back(std::make_unique<Ir>(args...));
      freeList.push_back(pool.back().get());
    }
  }

  /// Main thread: takes the returned spectra back into freeList.
  void reclaim() {
    const Ir* spent = nullptr;
    while (toMain.tryPop(spent)) freeList.push_back(const_cast<Ir*>(spent));
  }

  /// Main thread: reclaims, then the free spectrum to prepare next (it stays in freeList until
  /// pushed), or nullptr after yielding the CPU when none is free.
  Ir* nextFree() {
    reclaim();
    if (freeList.empty()) {
      std::this_thread::yield();
      return nullptr;
    }
    return freeList.back();
  }

  /// Audio thread: offers the newest IR sent to `convolver`; older ones not yet taken, and the
  /// newest if the convolver refuses it (a swap still under way), go to giveBack(ir).
  template <typename Convolver, typename GiveBack>
  Offer offerLatest(Convolver& convolver, GiveBack&& giveBack) {
    const Ir* latest = nullptr;
    const Ir* ir = nullptr;
    while (toAudio.tryPop(ir)) {
      if (latest) giveBack(latest);
      latest = ir;
    }
    if (!latest) return Offer::nothing;
    if (convolver.setNextIr(latest)) return Offer::taken;
    giveBack(latest);
    return Offer::refused;
  }
};

}  // namespace dpc::test
