// The IR hand-over of docs/design.md "Audio side" under ThreadSanitizer (scripts/tsan.sh): the
// main thread prepares IrSpectra (writes their spectra), passes pointers to an audio-role
// thread through a FixedRing (common/fixed_ring.h), the audio thread convolves with them
// (reads the spectra) and returns spent ones through a second ring, after which the main
// thread overwrites them. Any missing happens-before edge between a prepare() and the
// convolver's reads, or between the convolver's last read and the next prepare(), is a data
// race TSan reports. The ring synchronises with acquire/release atomics only (no standalone
// fences), which TSan models without annotations. Built without the interposing allocator
// (TSan replaces malloc itself); in ordinary builds it runs as a plain functional test.
//
// Negative control (not yet re-run with FixedRing): compiled with -DDPC_TSAN_INJECT_RACE the
// main thread also rewrites a spectrum right after handing it over, which TSan must report as
// a race between IrSpectrum::prepare and the convolver's reads.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <thread>
#include <vector>

#include "common/fixed_ring.h"
#include "audio/convolver.h"

using dpc::audio::ConvolverLayout;
using dpc::audio::IrSpectra;
using dpc::audio::PartitionedConvolver;

TEST_CASE("IR hand-over through SPSC queues is race-free", "[rt][tsan]") {
  constexpr int kBlock = 64;
  constexpr int kChannels = 2;
  constexpr size_t kIrSamples = 2048;
  constexpr int kPool = 4;
  constexpr int kMinBlocks = 4000;
  constexpr int kMinSwaps = 200;

  ConvolverLayout layout(kBlock, kIrSamples);
  PartitionedConvolver convolver(layout, kChannels);
  std::vector<std::unique_ptr<IrSpectra>> pool;
  std::vector<IrSpectra*> freeList;
  for (int i = 0; i < kPool; ++i) {
    pool.push_back(std::make_unique<IrSpectra>(layout, kChannels));
    freeList.push_back(pool.back().get());
  }
  dpc::FixedRing<const IrSpectra*> toAudio(kPool);
  dpc::FixedRing<const IrSpectra*> toMain(kPool);
  std::atomic<bool> audioDone{false};
  std::atomic<int> blocks{0}, swaps{0};
  std::atomic<int> queueFull{0};  // Catch2 assertions are not thread-safe: count, check later
  float peak = 0.0f;

  std::thread audio([&] {
    float input[kBlock];
    float outputs[kChannels][kBlock];
    float* out[kChannels] = {outputs[0], outputs[1]};
    int s = 0;
    auto giveBack = [&](const IrSpectra* spent) {
      if (!toMain.tryPush(spent)) queueFull.fetch_add(1, std::memory_order_relaxed);
    };
    // Runs until both enough blocks and enough swaps happened (the main thread's pace
    // varies, especially under TSan), bounded by a deadline.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    int b = 0;
    for (; (b < kMinBlocks || s < kMinSwaps) && std::chrono::steady_clock::now() < deadline; ++b) {
      const IrSpectra* latest = nullptr;
      const IrSpectra* ir = nullptr;
      while (toAudio.tryPop(ir)) {
        if (latest) giveBack(latest);
        latest = ir;
      }
      if (latest) {
        if (convolver.setNextIr(latest)) {
          ++s;
        } else {
          giveBack(latest);
        }
      }
      for (int i = 0; i < kBlock; ++i) input[i] = (i == 0 && b % 50 == 0) ? 1.0f : 0.0f;
      convolver.process(input, out);
      for (const auto& channel : outputs) {
        for (float v : channel) peak = std::max(peak, std::fabs(v));
      }
      while (const IrSpectra* spent = convolver.takeRetired()) giveBack(spent);
    }
    blocks.store(b, std::memory_order_relaxed);
    swaps.store(s, std::memory_order_relaxed);
    audioDone.store(true, std::memory_order_release);
  });

  std::vector<std::vector<float>> ir(kChannels, std::vector<float>(kIrSamples));
  std::vector<const float*> irPointers(kChannels);
  int version = 0;
  while (!audioDone.load(std::memory_order_acquire)) {
    const IrSpectra* spent = nullptr;
    while (toMain.tryPop(spent)) freeList.push_back(const_cast<IrSpectra*>(spent));
    if (freeList.empty()) {
      std::this_thread::yield();
      continue;
    }
    ++version;
    for (int c = 0; c < kChannels; ++c) {
      for (size_t n = 0; n < kIrSamples; ++n) {
        ir[size_t(c)][n] = float((version + c) % 7) * 0.1f * std::exp(-0.003f * float(n));
      }
      irPointers[size_t(c)] = ir[size_t(c)].data();
    }
    IrSpectra* next = freeList.back();
    next->prepare(irPointers.data(), kIrSamples);
    if (toAudio.tryPush(next)) freeList.pop_back();
#ifdef DPC_TSAN_INJECT_RACE
    // Negative control (manual): overwrite a spectrum the audio thread may be reading.
    next->prepare(irPointers.data(), kIrSamples);
#endif
    std::this_thread::yield();
  }
  audio.join();
  std::printf("tsan hand-over: %d blocks, %d IR swaps, %d IRs prepared, peak %.3f\n", blocks.load(),
              swaps.load(), version, double(peak));
  CHECK(queueFull.load() == 0);
  CHECK(blocks.load() >= kMinBlocks);
  CHECK(swaps.load() >= kMinSwaps);
  CHECK(peak > 0.0f);
}
