// Heap calls on the real audio thread: AudioOutput through a JACK server (dummy backend)
// renders a 2-channel partitioned convolution for 2 s; the interposing allocator counts every
// heap call made on PortAudio's callback thread from the first callback on (the wrapper's
// trampoline, the convolver, and PortAudio/JACK code between callbacks). Needs DPC_JACK=1:
//   scripts/jack-headless.sh build-dev/tests/jack_rt_test -s
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "audio/audio_output.h"
#include "audio/convolver.h"
#include "tests/rt/alloc_counter.h"
#include "tests/rt/rt_helpers.h"

namespace audio = dpc::audio;

namespace {

struct Render {
  audio::PartitionedConvolver* convolver = nullptr;
  std::vector<float> input;  // one block, sized before the stream starts
  uint32_t lcg = 1;
};

void render(void* user, float* const* out, int frames) noexcept {
  dpc::rt::markAudioThread(true);  // from the first callback on, for the thread's lifetime
  auto* r = static_cast<Render*>(user);
  for (int i = 0; i < frames; ++i) r->input[size_t(i)] = dpc::test::lcgNoise(r->lcg, 0.1f);
  r->convolver->process(r->input.data(), out);
}

}  // namespace

TEST_CASE("JACK: convolution on the PortAudio callback thread makes no heap calls", "[jack][rt]") {
  const char* jack = std::getenv("DPC_JACK");
  if (!jack || std::string(jack) != "1") {
    WARN("skipped: DPC_JACK != 1 (run under scripts/jack-headless.sh)");
    return;
  }
  constexpr int kBlock = 128;
  constexpr size_t kIrSamples = 24000;  // 0.5 s at 48 kHz: 188 partitions
  audio::ConvolverLayout layout(kBlock, kIrSamples);
  audio::PartitionedConvolver convolver(layout, 2);
  audio::IrSpectra ir(layout, 2);
  std::vector<float> h(kIrSamples);
  for (size_t n = 0; n < kIrSamples; ++n) {
    h[n] = ((n * 7919) % 13 - 6.0f) / 60.0f * std::exp(-6.9f * float(n) / float(kIrSamples));
  }
  const float* irs[2] = {h.data(), h.data()};
  ir.prepare(irs, kIrSamples);
  REQUIRE(convolver.setNextIr(&ir));

  Render r;
  r.convolver = &convolver;
  r.input.assign(kBlock, 0.0f);
  audio::AudioOutput::Options options;
  options.device = "jack:";
  options.blockSize = kBlock;
  options.channels = 2;
  audio::AudioOutput out(options, &render, &r);

  dpc::rt::resetAudioThreadAllocations();
  out.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const audio::CallbackStats::Snapshot warm = out.stats().snapshot();
  const auto sched = out.callbackScheduling();  // reported, not asserted: jackd -R decides
  std::printf("callback thread scheduling: %s %d (%s)\n", sched.policy, sched.priority,
              sched.realTime ? "real-time" : "not real-time");
  CHECK(sched.known);
  std::this_thread::sleep_for(std::chrono::milliseconds(1700));
  out.stop();
  const dpc::rt::AllocationCounts counts = dpc::rt::audioThreadAllocations();

  const audio::CallbackStats::Snapshot all = out.stats().snapshot();
  std::printf("%s\n", out.statusLine().c_str());
  std::printf("after the first 0.3 s: %s\n", out.statusLine(warm).c_str());
  std::printf("callback median %llu ns, p99.9 %llu ns, max %llu ns; block %.0f ns\n",
              static_cast<unsigned long long>(all.quantileNs(0.5)),
              static_cast<unsigned long long>(all.quantileNs(0.999)),
              static_cast<unsigned long long>(all.maxNs), out.blockPeriodNs());
  std::printf("heap calls on the callback thread: %llu\n",
              static_cast<unsigned long long>(counts.total()));
  if (counts.total() > 0) {
    char buf[512];
    std::printf("first from %s\n",
                dpc::rt::describeAddress(dpc::rt::firstAudioAllocationCaller(), buf, sizeof buf));
  }
  const double expected = 2.0 * out.sampleRate() / kBlock;
  CHECK(double(all.callbacks) > 0.9 * expected);
  CHECK(counts.total() == 0);
  // The retired list is only touched by the audio thread, which is stopped now.
  while (convolver.takeRetired()) {
  }
}
