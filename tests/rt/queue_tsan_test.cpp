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
#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <thread>
#include <vector>

#include "audio/convolver.h"
#include "tests/rt/rt_helpers.h"

using dpc::audio::ConvolverLayout;
using dpc::audio::IrSpectra;
using dpc::audio::PartitionedConvolver;
using dpc::test::Offer;

TEST_CASE("IR hand-over through SPSC queues is race-free", "[rt][tsan]") {
  constexpr dpc::test::HandOverSpec kSpec{
      .block = 64, .channels = 2, .irSamples = 2048, .pool = 4, .minBlocks = 4000, .minSwaps = 200};
  ConvolverLayout layout(kSpec.block, kSpec.irSamples);
  PartitionedConvolver convolver(layout, kSpec.channels);
  dpc::test::IrHandOver<IrSpectra> handOver(kSpec.pool, layout, kSpec.channels);
  std::atomic<bool> audioDone{false};
  std::atomic<uint64_t> blocks{0}, swaps{0};
  std::atomic<int> queueFull{0};  // Catch2 assertions are not thread-safe: count, check later
  float peak = 0.0f;

  std::thread audio([&] {
    float input[kSpec.block];
    float outputs[kSpec.channels][kSpec.block];
    float* out[kSpec.channels] = {outputs[0], outputs[1]};
    uint64_t s = 0;
    auto giveBack = [&](const IrSpectra* spent) {
      if (!handOver.toMain.tryPush(spent)) queueFull.fetch_add(1, std::memory_order_relaxed);
    };
    const auto deadline = kSpec.deadline();
    uint64_t b = 0;
    for (; kSpec.running(b, s, deadline); ++b) {
      if (handOver.offerLatest(convolver, giveBack) == Offer::taken) ++s;
      for (int i = 0; i < kSpec.block; ++i) input[i] = (i == 0 && b % 50 == 0) ? 1.0f : 0.0f;
      convolver.process(input, out);
      for (const auto& channel : outputs) {
        for (float v : channel) peak = std::max(peak, std::fabs(v));
      }
      dpc::test::returnRetired(convolver, giveBack);
    }
    blocks.store(b, std::memory_order_relaxed);
    swaps.store(s, std::memory_order_relaxed);
    audioDone.store(true, std::memory_order_release);
  });

  std::vector<std::vector<float>> ir(kSpec.channels, std::vector<float>(kSpec.irSamples));
  std::vector<const float*> irPointers(kSpec.channels);
  int version = 0;
  while (!audioDone.load(std::memory_order_acquire)) {
    IrSpectra* next = handOver.nextFree();
    if (!next) continue;
    ++version;
    for (int c = 0; c < kSpec.channels; ++c) {
      for (size_t n = 0; n < kSpec.irSamples; ++n) {
        ir[size_t(c)][n] = float((version + c) % 7) * 0.1f * std::exp(-0.003f * float(n));
      }
      irPointers[size_t(c)] = ir[size_t(c)].data();
    }
    next->prepare(irPointers.data(), kSpec.irSamples);
    if (handOver.toAudio.tryPush(next)) handOver.freeList.pop_back();
#ifdef DPC_TSAN_INJECT_RACE
    // Negative control (manual): overwrite a spectrum the audio thread may be reading.
    next->prepare(irPointers.data(), kSpec.irSamples);
#endif
    std::this_thread::yield();
  }
  audio.join();
  std::printf("tsan hand-over: %llu blocks, %llu IR swaps, %d IRs prepared, peak %.3f\n",
              static_cast<unsigned long long>(blocks.load()),
              static_cast<unsigned long long>(swaps.load()), version, double(peak));
  CHECK(queueFull.load() == 0);
  CHECK(blocks.load() >= kSpec.minBlocks);
  CHECK(swaps.load() >= kSpec.minSwaps);
  CHECK(peak > 0.0f);
}
