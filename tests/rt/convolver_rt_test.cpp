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

#include "common/fixed_ring.h"
#include "audio/convolver.h"
#include "audio/nonuniform_convolver.h"
#include "tests/rt/alloc_counter.h"

using dpc::audio::ConvolverLayout;
using dpc::audio::IrSpectra;
using dpc::audio::PartitionedConvolver;
using dpc::rt::AllocationCounts;
using dpc::rt::AllocationScope;

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

/// A decaying noise IR with a per-version seed, so successive IRs differ.
void makeIr(std::vector<std::vector<float>>& ir, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  for (auto& channel : ir) {
    for (size_t n = 0; n < channel.size(); ++n) {
      channel[n] = 0.1f * noise(rng) * std::exp(-6.9f * float(n) / float(channel.size()));
    }
  }
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

TEST_CASE("Convolver IR swaps through SPSC queues: zero heap calls on the audio thread",
          "[rt][convolver]") {
  constexpr int kBlock = 128;
  constexpr int kChannels = 2;
  constexpr size_t kIrSamples = 12000;  // 0.25 s at 48 kHz: 94 partitions
  constexpr int kPool = 6;
  constexpr uint64_t kMinBlocks = 5000;
  constexpr uint64_t kMinSwaps = 300;

  ConvolverLayout layout(kBlock, kIrSamples);
  PartitionedConvolver convolver(layout, kChannels);
  std::vector<std::unique_ptr<IrSpectra>> pool;
  std::vector<IrSpectra*> freeList;
  for (int i = 0; i < kPool; ++i) {
    pool.push_back(std::make_unique<IrSpectra>(layout, kChannels));
    freeList.push_back(pool.back().get());
  }
  // Capacities fixed up front: every pointer fits in either queue, so tryPush can only
  // fail if a pointer were duplicated.
  dpc::FixedRing<const IrSpectra*> toAudio(kPool);
  dpc::FixedRing<const IrSpectra*> toMain(kPool);

  std::atomic<bool> audioDone{false};
  std::atomic<uint64_t> blocks{0}, swaps{0}, refused{0}, returnFailures{0};
  AllocationCounts audioCounts;
  float peak = 0.0f;
  bool finite = true;

  std::thread audio([&] {
    // Everything the loop needs exists before the scope opens.
    float input[kBlock];
    float outputs[kChannels][kBlock];
    float* out[kChannels] = {outputs[0], outputs[1]};
    const IrSpectra* unreturned[2 * kPool];
    int numUnreturned = 0;
    uint32_t lcg = 12345;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);

    AllocationScope scope;
    auto giveBack = [&](const IrSpectra* ir) {
      if (!toMain.tryPush(ir)) {
        returnFailures.fetch_add(1, std::memory_order_relaxed);
        unreturned[numUnreturned++] = ir;  // retried next block
      }
    };
    uint64_t b = 0, s = 0;
    while ((b < kMinBlocks || s < kMinSwaps) && std::chrono::steady_clock::now() < deadline) {
      for (int i = 0; i < numUnreturned;) {
        if (toMain.tryPush(unreturned[i])) {
          unreturned[i] = unreturned[--numUnreturned];
        } else {
          ++i;
        }
      }
      // Newest IR wins; older ones not yet taken go straight back.
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
          refused.fetch_add(1, std::memory_order_relaxed);
          giveBack(latest);
        }
      }
      for (int i = 0; i < kBlock; ++i) {
        lcg = lcg * 1664525u + 1013904223u;
        input[i] = float(int32_t(lcg)) * (0.5f / 2147483648.0f);
      }
      for (auto& channel : outputs) std::fill(channel, channel + kBlock, 0.0f);
      convolver.processAdd(input, out);
      for (const auto& channel : outputs) {
        for (float v : channel) {
          finite = finite && std::isfinite(v);
          peak = std::max(peak, std::fabs(v));
        }
      }
      while (const IrSpectra* spent = convolver.takeRetired()) giveBack(spent);
      ++b;
      blocks.store(b, std::memory_order_relaxed);
      swaps.store(s, std::memory_order_relaxed);
    }
    audioCounts = scope.counts();
    for (int i = 0; i < numUnreturned; ++i) toMain.tryPush(unreturned[i]);  // outside scope
    audioDone.store(true, std::memory_order_release);
  });

  // Propagation role: allocate freely, prepare IRs, hand them over, recycle spent ones.
  std::vector<std::vector<float>> ir(kChannels, std::vector<float>(kIrSamples));
  std::vector<const float*> irPointers(kChannels);
  uint32_t version = 0;
  uint64_t prepared = 0;
  while (!audioDone.load(std::memory_order_acquire)) {
    const IrSpectra* spent = nullptr;
    while (toMain.tryPop(spent)) freeList.push_back(const_cast<IrSpectra*>(spent));
    if (freeList.empty()) {
      std::this_thread::yield();
      continue;
    }
    IrSpectra* next = freeList.back();
    // Vary the length too (including a short one), so activePartitions() changes.
    const size_t n = (version % 5 == 4) ? kIrSamples / 7 : kIrSamples - 97 * (version % 5);
    makeIr(ir, ++version);
    for (int c = 0; c < kChannels; ++c) irPointers[size_t(c)] = ir[size_t(c)].data();
    next->prepare(irPointers.data(), n);
    if (toAudio.tryPush(next)) {
      freeList.pop_back();
      ++prepared;
    }
  }
  audio.join();

  // Account for every spectrum: free, queued either way, or held by the convolver.
  const IrSpectra* p = nullptr;
  while (toMain.tryPop(p)) freeList.push_back(const_cast<IrSpectra*>(p));
  size_t held = freeList.size();
  while (toAudio.tryPop(p)) ++held;
  if (convolver.currentIr()) ++held;
  if (convolver.hasPending() && convolver.pendingIr()) ++held;
  while (convolver.takeRetired()) ++held;

  std::printf(
      "audio thread: %llu blocks of %d frames x %d channels, %llu IR swaps (%llu prepared, "
      "%llu refused, %llu return-queue retries), peak %.3f\n",
      static_cast<unsigned long long>(blocks.load()), kBlock, kChannels,
      static_cast<unsigned long long>(swaps.load()), static_cast<unsigned long long>(prepared),
      static_cast<unsigned long long>(refused.load()),
      static_cast<unsigned long long>(returnFailures.load()), double(peak));
  printCounts("audio thread", audioCounts);

  CHECK(blocks.load() >= kMinBlocks);
  CHECK(swaps.load() >= kMinSwaps);
  CHECK(finite);
  CHECK(peak > 0.0f);
  CHECK(held == size_t(kPool));
  CHECK(returnFailures.load() == 0);
  CHECK(audioCounts.total() == 0);
}

TEST_CASE(
    "Non-uniform convolver, several sources, IR set swaps through SPSC queues: zero heap "
    "calls on the audio thread",
    "[rt][convolver]") {
  using dpc::audio::NonUniformConvolver;
  using dpc::audio::NonUniformIrSet;
  using dpc::audio::NonUniformLayout;
  constexpr int kBlock = 64;
  constexpr int kSources = 3;
  constexpr int kChannels = 2;
  constexpr size_t kIrSamples = 30000;  // levels of 64, 256, 1024, 4096 samples
  constexpr int kPool = 16;             // a set per level in use, one pending, spares
  constexpr uint64_t kMinBlocks = 6000;
  constexpr uint64_t kMinSwaps = 300;

  NonUniformLayout layout(kBlock, kIrSamples, 4096);
  REQUIRE(layout.numLevels() == 4);
  NonUniformConvolver convolver(layout, kSources, kChannels);
  std::vector<std::unique_ptr<NonUniformIrSet>> pool;
  std::vector<NonUniformIrSet*> freeList;
  for (int i = 0; i < kPool; ++i) {
    pool.push_back(std::make_unique<NonUniformIrSet>(layout, kSources, kChannels));
    freeList.push_back(pool.back().get());
  }
  dpc::FixedRing<const NonUniformIrSet*> toAudio(kPool);
  dpc::FixedRing<const NonUniformIrSet*> toMain(kPool);

  std::atomic<bool> audioDone{false};
  std::atomic<uint64_t> blocks{0}, swaps{0}, refused{0};
  AllocationCounts audioCounts;
  float peak = 0.0f;
  bool finite = true;

  std::thread audio([&] {
    float input[kSources][kBlock];
    const float* in[kSources] = {input[0], input[1], input[2]};
    float outputs[kChannels][kBlock];
    float* out[kChannels] = {outputs[0], outputs[1]};
    uint32_t lcg = 777;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    AllocationScope scope;
    uint64_t b = 0, s = 0;
    while ((b < kMinBlocks || s < kMinSwaps) && std::chrono::steady_clock::now() < deadline) {
      // Newest set wins; older ones not yet taken go straight back (the queue has room for
      // every set, so tryPush cannot fail).
      const NonUniformIrSet* latest = nullptr;
      const NonUniformIrSet* ir = nullptr;
      while (toAudio.tryPop(ir)) {
        if (latest) toMain.tryPush(latest);
        latest = ir;
      }
      if (latest) {
        if (convolver.setNextIr(latest)) {
          ++s;
        } else {
          refused.fetch_add(1, std::memory_order_relaxed);
          toMain.tryPush(latest);
        }
      }
      for (auto& channel : input)
        for (float& v : channel) {
          lcg = lcg * 1664525u + 1013904223u;
          v = float(int32_t(lcg)) * (0.5f / 2147483648.0f);
        }
      convolver.process(in, out);
      for (const auto& channel : outputs)
        for (float v : channel) {
          finite = finite && std::isfinite(v);
          peak = std::max(peak, std::fabs(v));
        }
      while (const NonUniformIrSet* spent = convolver.takeRetired()) toMain.tryPush(spent);
      ++b;
      blocks.store(b, std::memory_order_relaxed);
      swaps.store(s, std::memory_order_relaxed);
    }
    audioCounts = scope.counts();
    audioDone.store(true, std::memory_order_release);
  });

  std::vector<std::vector<float>> ir(kChannels, std::vector<float>(kIrSamples));
  std::vector<const float*> irPointers(kChannels);
  uint32_t version = 0;
  while (!audioDone.load(std::memory_order_acquire)) {
    const NonUniformIrSet* spent = nullptr;
    while (toMain.tryPop(spent)) freeList.push_back(const_cast<NonUniformIrSet*>(spent));
    if (freeList.empty()) {
      std::this_thread::yield();
      continue;
    }
    NonUniformIrSet* next = freeList.back();
    const size_t n = (version % 4 == 3) ? kIrSamples / 11 : kIrSamples - 313 * (version % 4);
    makeIr(ir, ++version);
    for (int c = 0; c < kChannels; ++c) irPointers[size_t(c)] = ir[size_t(c)].data();
    for (int s = 0; s < kSources; ++s) next->prepare(s, irPointers.data(), n);
    if (toAudio.tryPush(next)) freeList.pop_back();
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  audio.join();

  // Every set is free, queued, or still used by the convolver.
  const NonUniformIrSet* p = nullptr;
  while (toMain.tryPop(p)) freeList.push_back(const_cast<NonUniformIrSet*>(p));
  while (toAudio.tryPop(p)) freeList.push_back(const_cast<NonUniformIrSet*>(p));
  // Fade every level out to silence: then no set is in use and all must come back.
  REQUIRE(convolver.setNextIr(nullptr));
  {
    float zeros[kBlock] = {}, sink[kChannels][kBlock];
    const float* in[kSources] = {zeros, zeros, zeros};
    float* out[kChannels] = {sink[0], sink[1]};
    for (int k = 0; k < 4 * 4096 / kBlock && convolver.swapping(); ++k) {
      convolver.process(in, out);
      while ((p = convolver.takeRetired())) freeList.push_back(const_cast<NonUniformIrSet*>(p));
    }
  }
  while ((p = convolver.takeRetired())) freeList.push_back(const_cast<NonUniformIrSet*>(p));
  std::printf(
      "non-uniform audio thread: %llu blocks, %d sources x %d channels, %llu swaps "
      "(%llu refused), peak %.3f\n",
      static_cast<unsigned long long>(blocks.load()), kSources, kChannels,
      static_cast<unsigned long long>(swaps.load()),
      static_cast<unsigned long long>(refused.load()), double(peak));
  printCounts("non-uniform audio thread", audioCounts);
  CHECK(blocks.load() >= kMinBlocks);
  CHECK(swaps.load() >= kMinSwaps);
  CHECK(finite);
  CHECK(peak > 0.0f);
  CHECK_FALSE(convolver.swapping());
  CHECK(freeList.size() == size_t(kPool));
  CHECK(audioCounts.total() == 0);
}
