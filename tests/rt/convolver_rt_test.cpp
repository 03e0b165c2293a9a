// Real-time safety of the audio side's IR hand-over: a thread in the audio role runs
// thousands of PartitionedConvolver blocks while the main thread (propagation role) prepares
// new IrSpectra and passes pointers over a fixed-capacity SPSC queue, getting spent ones back
// through a second queue (docs/design.md "Audio side"). The interposing allocator
// (alloc_counter.cpp) must count zero heap calls on the audio thread.

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "audio/convolver.h"
#include "audio/nonuniform_convolver.h"
#include "common/fixed_ring.h"
#include "tests/rt/alloc_counter.h"
#include "tests/rt/rt_helpers.h"

using dpc::audio::ConvolverLayout;
using dpc::audio::IrSpectra;
using dpc::audio::NonUniformConvolver;
using dpc::audio::NonUniformIrSet;
using dpc::audio::NonUniformLayout;
using dpc::audio::PartitionedConvolver;
using dpc::rt::AllocationCounts;
using dpc::rt::AllocationScope;
using dpc::test::Offer;

namespace {

/// Keeps the compiler from eliding an allocation whose result is otherwise unused.
void escape(void* p) {
  asm volatile("" : : "g"(p) : "memory");
}

void printCounts(const char* what, const AllocationCounts& c) {
  std::printf(
      "%s: %llu heap calls (malloc %llu calloc %llu realloc %llu free %llu aligned %llu new "
      "%llu delete %llu)\n",
      what, static_cast<unsigned long long>(c.total()), static_cast<unsigned long long>(c.malloc),
      static_cast<unsigned long long>(c.calloc), static_cast<unsigned long long>(c.realloc),
      static_cast<unsigned long long>(c.free), static_cast<unsigned long long>(c.aligned),
      static_cast<unsigned long long>(c.newCalls), static_cast<unsigned long long>(c.deleteCalls));
  if (c.total() > 0) {
    char buf[512];
    std::printf("first counted call from %s\n",
                dpc::rt::describeAddress(dpc::rt::firstAudioAllocationCaller(), buf, sizeof buf));
  }
}

/// Decaying noise IRs per channel, a new one per version (the seed), so successive IRs differ,
/// and the per-channel pointers prepare() takes.
class NoiseIr {
 public:
  NoiseIr(int channels, size_t samples)
      : ir_(size_t(channels), std::vector<float>(samples)), pointers_(size_t(channels)) {
    for (size_t c = 0; c < ir_.size(); ++c) pointers_[c] = ir_[c].data();
  }
  /// The length to prepare the next version with, varied so activePartitions() changes: over
  /// `period` versions the full length minus 0, step, 2 step, ..., and last a short one,
  /// the full length / shortDivisor.
  size_t nextLength(uint32_t period, size_t step, size_t shortDivisor) const {
    const size_t samples = ir_.front().size();
    return (version_ % period == period - 1) ? samples / shortDivisor
                                             : samples - step * (version_ % period);
  }
  /// The next version, all channels.
  const float* const* make() {
    std::mt19937 rng(++version_);
    std::normal_distribution<float> noise(0.0f, 1.0f);
    for (auto& channel : ir_) {
      for (size_t n = 0; n < channel.size(); ++n) {
        channel[n] = 0.1f * noise(rng) * std::exp(-6.9f * float(n) / float(channel.size()));
      }
    }
    return pointers_.data();
  }

 private:
  std::vector<std::vector<float>> ir_;
  std::vector<const float*> pointers_;
  uint32_t version_ = 0;
};

/// The audio thread's blocks and IR swaps: counted there in b and s, published in the atomics
/// for the main thread after every block.
struct AudioProgress {
  std::atomic<uint64_t> blocks{0}, swaps{0}, refused{0};
  uint64_t b = 0, s = 0;

  void offered(Offer offer) {
    if (offer == Offer::taken) ++s;
    if (offer == Offer::refused) refused.fetch_add(1, std::memory_order_relaxed);
  }
  void blockDone() {
    ++b;
    blocks.store(b, std::memory_order_relaxed);
    swaps.store(s, std::memory_order_relaxed);
  }
};

/// Adds one block of `outputs` to the test's running peak and finiteness.
template <size_t Channels, size_t Frames>
void track(const float (&outputs)[Channels][Frames], float& peak, bool& finite) {
  for (const auto& channel : outputs) {
    for (float v : channel) {
      finite = finite && std::isfinite(v);
      peak = std::max(peak, std::fabs(v));
    }
  }
}

/// The audio thread's way back to the main thread: a spectrum that finds the ring full is
/// counted in `failures` and retried before the next block (retry()), and pushed once more,
/// outside the allocation scope, at the end (flush()). No allocation.
template <int Capacity>
class RetryingReturn {
 public:
  RetryingReturn(dpc::FixedRing<const IrSpectra*>& ring, std::atomic<uint64_t>& failures)
      : ring_(ring), failures_(failures) {}
  void operator()(const IrSpectra* ir) {
    if (!ring_.tryPush(ir)) {
      failures_.fetch_add(1, std::memory_order_relaxed);
      unreturned_[numUnreturned_++] = ir;
    }
  }
  void retry() {
    for (int i = 0; i < numUnreturned_;) {
      if (ring_.tryPush(unreturned_[i])) {
        unreturned_[i] = unreturned_[--numUnreturned_];
      } else {
        ++i;
      }
    }
  }
  void flush() {
    for (int i = 0; i < numUnreturned_; ++i) ring_.tryPush(unreturned_[i]);
  }

 private:
  dpc::FixedRing<const IrSpectra*>& ring_;
  std::atomic<uint64_t>& failures_;
  const IrSpectra* unreturned_[Capacity];
  int numUnreturned_ = 0;
};

/// Main thread, after the audio thread ended: the spectra free, queued either way, or held by
/// the convolver.
size_t countHeld(dpc::test::IrHandOver<IrSpectra>& handOver, PartitionedConvolver& convolver) {
  handOver.reclaim();
  size_t held = handOver.freeList.size();
  const IrSpectra* p = nullptr;
  while (handOver.toAudio.tryPop(p)) ++held;
  if (convolver.currentIr()) ++held;
  if (convolver.hasPending() && convolver.pendingIr()) ++held;
  while (convolver.takeRetired()) ++held;
  return held;
}

/// Fades every level of `convolver` out to silence (for at most four blocks of the longest
/// level of 4096 samples), returning each set it lets go to freeList.
template <int Block, int Sources, int Channels>
void fadeOutAll(NonUniformConvolver& convolver, std::vector<NonUniformIrSet*>& freeList) {
  auto release = [&] {
    while (const NonUniformIrSet* p = convolver.takeRetired())
      freeList.push_back(const_cast<NonUniformIrSet*>(p));
  };
  REQUIRE(convolver.setNextIr(nullptr));
  float zeros[Block] = {}, sink[Channels][Block];
  const float* in[Sources] = {zeros, zeros, zeros};
  float* out[Channels] = {sink[0], sink[1]};
  for (int k = 0; k < 4 * 4096 / Block && convolver.swapping(); ++k) {
    convolver.process(in, out);
    release();
  }
  release();
}

}  // namespace

TEST_CASE("The counter sees heap calls on the marked thread only", "[rt][alloc_counter]") {
  AllocationCounts marked, unmarked;
  std::thread([&] {
    AllocationScope scope;
    auto* v = new std::vector<float>(1000);
    escape(v);
    delete v;
    void* p = std::malloc(100);
    escape(p);
    p = std::realloc(p, 1000);
    escape(p);
    std::free(p);
    marked = scope.counts();
  }).join();
  std::thread([&] {
    const AllocationCounts before = dpc::rt::audioThreadAllocations();
    auto* v = new std::vector<float>(1000);
    escape(v);
    delete v;
    unmarked = dpc::rt::audioThreadAllocations() - before;
  }).join();
  printCounts("marked thread, deliberate allocations", marked);
  CHECK(marked.newCalls >= 2);  // the vector object and its buffer
  CHECK(marked.deleteCalls >= 2);
  CHECK(marked.malloc >= 1);
  CHECK(marked.realloc == 1);
  CHECK(marked.free >= 1);
  CHECK(dpc::rt::firstAudioAllocationCaller() != nullptr);
  CHECK(unmarked.total() == 0);
  CHECK_FALSE(dpc::rt::isMarkedAudioThread());
}

TEST_CASE("FixedRing: tryPush and tryPop never allocate, full or not", "[rt][alloc_counter]") {
  dpc::FixedRing<int*> ring(4);  // allocates here, on the main thread
  AllocationCounts tryCounts;
  std::thread([&] {
    AllocationScope scope;
    int rejected = 0;
    for (int i = 0; i < 100; ++i) {
      if (!ring.tryPush(nullptr)) ++rejected;
      if (i % 3 == 0) {
        int* p;
        ring.tryPop(p);
      }
    }
    CHECK(rejected > 0);
    tryCounts = scope.counts();
  }).join();
  printCounts("tryPush/tryPop x 100", tryCounts);
  CHECK(tryCounts.total() == 0);
  CHECK(ring.overflows() > 0);
}

namespace {

/// Propagation role: allocate freely, prepare IRs (lengths including a short one), hand them
/// over, recycle spent ones, until the audio thread is done. Returns the IRs handed over.
uint64_t feedUniform(dpc::test::IrHandOver<IrSpectra>& handOver, NoiseIr& ir,
                     const std::atomic<bool>& audioDone) {
  uint64_t prepared = 0;
  while (!audioDone.load(std::memory_order_acquire)) {
    IrSpectra* next = handOver.nextFree();
    if (!next) continue;
    const size_t n = ir.nextLength(5, 97, 7);
    next->prepare(ir.make(), n);
    if (handOver.toAudio.tryPush(next)) {
      handOver.freeList.pop_back();
      ++prepared;
    }
  }
  return prepared;
}

/// The same for IR sets of `sources` sources, one every 200 us.
void feedNonUniform(dpc::test::IrHandOver<NonUniformIrSet>& handOver, NoiseIr& ir, int sources,
                    const std::atomic<bool>& audioDone) {
  while (!audioDone.load(std::memory_order_acquire)) {
    NonUniformIrSet* next = handOver.nextFree();
    if (!next) continue;
    const size_t n = ir.nextLength(4, 313, 11);
    const float* const* channels = ir.make();
    for (int s = 0; s < sources; ++s) next->prepare(s, channels, n);
    if (handOver.toAudio.tryPush(next)) handOver.freeList.pop_back();
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

}  // namespace

TEST_CASE("Convolver IR swaps through SPSC queues: zero heap calls on the audio thread",
          "[rt][convolver]") {
  constexpr dpc::test::HandOverSpec kSpec{.block = 128,
                                          .channels = 2,
                                          .irSamples = 12000,  // 0.25 s at 48 kHz: 94 partitions
                                          .pool = 6,
                                          .minBlocks = 5000,
                                          .minSwaps = 300};
  constexpr int kBlock = kSpec.block;
  constexpr int kChannels = kSpec.channels;
  ConvolverLayout layout(kBlock, kSpec.irSamples);
  PartitionedConvolver convolver(layout, kChannels);
  dpc::test::IrHandOver<IrSpectra> handOver(kSpec.pool, layout, kChannels);

  std::atomic<bool> audioDone{false};
  AudioProgress progress;
  std::atomic<uint64_t> returnFailures{0};
  AllocationCounts audioCounts;
  float peak = 0.0f;
  bool finite = true;

  std::thread audio([&] {
    // Everything the loop needs exists before the scope opens.
    float input[kBlock];
    float outputs[kChannels][kBlock];
    float* out[kChannels] = {outputs[0], outputs[1]};
    RetryingReturn<2 * kSpec.pool> giveBack(handOver.toMain, returnFailures);
    uint32_t lcg = 12345;
    const auto deadline = kSpec.deadline();

    AllocationScope scope;
    while (kSpec.running(progress.b, progress.s, deadline)) {
      giveBack.retry();
      progress.offered(handOver.offerLatest(convolver, giveBack));
      for (int i = 0; i < kBlock; ++i) input[i] = dpc::test::lcgNoise(lcg, 0.5f);
      for (auto& channel : outputs) std::fill(channel, channel + kBlock, 0.0f);
      convolver.processAdd(input, out);
      track(outputs, peak, finite);
      dpc::test::returnRetired(convolver, giveBack);
      progress.blockDone();
    }
    audioCounts = scope.counts();
    giveBack.flush();
    audioDone.store(true, std::memory_order_release);
  });

  NoiseIr ir(kChannels, kSpec.irSamples);
  const uint64_t prepared = feedUniform(handOver, ir, audioDone);
  audio.join();

  // Account for every spectrum: free, queued either way, or held by the convolver.
  const size_t held = countHeld(handOver, convolver);

  std::printf(
      "audio thread: %llu blocks of %d frames x %d channels, %llu IR swaps (%llu prepared, "
      "%llu refused, %llu return-queue retries), peak %.3f\n",
      static_cast<unsigned long long>(progress.blocks.load()), kBlock, kChannels,
      static_cast<unsigned long long>(progress.swaps.load()),
      static_cast<unsigned long long>(prepared),
      static_cast<unsigned long long>(progress.refused.load()),
      static_cast<unsigned long long>(returnFailures.load()), double(peak));
  printCounts("audio thread", audioCounts);

  CHECK(progress.blocks.load() >= kSpec.minBlocks);
  CHECK(progress.swaps.load() >= kSpec.minSwaps);
  CHECK(finite);
  CHECK(peak > 0.0f);
  CHECK(held == size_t(kSpec.pool));
  CHECK(returnFailures.load() == 0);
  CHECK(audioCounts.total() == 0);
}

TEST_CASE(
    "Non-uniform convolver, several sources, IR set swaps through SPSC queues: zero heap "
    "calls on the audio thread",
    "[rt][convolver]") {
  constexpr int kSources = 3;
  constexpr dpc::test::HandOverSpec kSpec{
      .block = 64,
      .channels = 2,
      .irSamples = 30000,  // levels of 64, 256, 1024, 4096 samples
      .pool = 16,          // a set per level in use, one pending, spares
      .minBlocks = 6000,
      .minSwaps = 300};
  constexpr int kBlock = kSpec.block;
  constexpr int kChannels = kSpec.channels;

  NonUniformLayout layout(kBlock, kSpec.irSamples, 4096);
  REQUIRE(layout.numLevels() == 4);
  NonUniformConvolver convolver(layout, kSources, kChannels);
  dpc::test::IrHandOver<NonUniformIrSet> handOver(kSpec.pool, layout, kSources, kChannels);
  auto& freeList = handOver.freeList;

  std::atomic<bool> audioDone{false};
  AudioProgress progress;
  AllocationCounts audioCounts;
  float peak = 0.0f;
  bool finite = true;

  std::thread audio([&] {
    float input[kSources][kBlock];
    const float* in[kSources] = {input[0], input[1], input[2]};
    float outputs[kChannels][kBlock];
    float* out[kChannels] = {outputs[0], outputs[1]};
    uint32_t lcg = 777;
    const auto deadline = kSpec.deadline();
    AllocationScope scope;
    // The return ring has room for every set, so tryPush cannot fail.
    auto giveBack = [&](const NonUniformIrSet* spent) { handOver.toMain.tryPush(spent); };
    while (kSpec.running(progress.b, progress.s, deadline)) {
      progress.offered(handOver.offerLatest(convolver, giveBack));
      for (auto& channel : input)
        for (float& v : channel) v = dpc::test::lcgNoise(lcg, 0.5f);
      convolver.process(in, out);
      track(outputs, peak, finite);
      dpc::test::returnRetired(convolver, giveBack);
      progress.blockDone();
    }
    audioCounts = scope.counts();
    audioDone.store(true, std::memory_order_release);
  });

  NoiseIr ir(kChannels, kSpec.irSamples);
  feedNonUniform(handOver, ir, kSources, audioDone);
  audio.join();

  // Every set is free, queued, or still used by the convolver.
  handOver.reclaim();
  const NonUniformIrSet* p = nullptr;
  while (handOver.toAudio.tryPop(p)) freeList.push_back(const_cast<NonUniformIrSet*>(p));
  // Fade every level out to silence: then no set is in use and all must come back.
  fadeOutAll<kBlock, kSources, kChannels>(convolver, freeList);
  std::printf(
      "non-uniform audio thread: %llu blocks, %d sources x %d channels, %llu swaps "
      "(%llu refused), peak %.3f\n",
      static_cast<unsigned long long>(progress.blocks.load()), kSources, kChannels,
      static_cast<unsigned long long>(progress.swaps.load()),
      static_cast<unsigned long long>(progress.refused.load()), double(peak));
  printCounts("non-uniform audio thread", audioCounts);
  CHECK(progress.blocks.load() >= kSpec.minBlocks);
  CHECK(progress.swaps.load() >= kSpec.minSwaps);
  CHECK(finite);
  CHECK(peak > 0.0f);
  CHECK_FALSE(convolver.swapping());
  CHECK(freeList.size() == size_t(kSpec.pool));
  CHECK(audioCounts.total() == 0);
}
