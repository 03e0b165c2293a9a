// Real-time safety of the whole live pipeline: the audio thread's render() makes
// zero heap calls across thousands of blocks that include IR swaps, while the propagation
// thread computes frames and the control thread moves the listener.
#include <catch2/catch.hpp>

#include "alloc_counter.h"
#include "live_driver.h"

using namespace dpc;

namespace {
using rt::CountHeapCalls;

/// What every run checks: at least `swaps` IRs applied, no heap call on the audio thread,
/// finite output, no block refused as NaN.
void checkRun(const test::LiveRun& run, const CountHeapCalls& counter, uint64_t swaps) {
  INFO("blocks " << run.status.blocks << ", IRs applied " << run.status.irsApplied
                 << ", heap calls " << counter.calls);
  CHECK(run.status.irsApplied >= swaps);
  CHECK(counter.calls == 0);
  CHECK(run.finite);
  CHECK(run.status.nanBlocks == 0);
}
}  // namespace

TEST_CASE("LiveSession::render makes no heap calls across IR swaps", "[rt]") {
  CountHeapCalls counter;
  const int blocks = 4000;
  const uint64_t swaps = 100;  // swaps really happen during the counted blocks
  const test::LiveRun run = test::driveLiveSession(blocks, swaps, counter);
  checkRun(run, counter, swaps);
  CHECK(run.status.blocks >= uint64_t(blocks));
  CHECK(run.recordedFrames == size_t(run.status.blocks) * 128);  // the recorder lost nothing
}

// Hybrid rendering adds the late buses' mixer and convolver to the audio thread: still no heap
// call, across swaps of both IR parts at once.
TEST_CASE("LiveSession::render in hybrid rendering makes no heap calls across IR swaps", "[rt]") {
  CountHeapCalls counter;
  const test::LiveRun run = test::driveLiveSession(2000, 50, counter, 0, Rendering::kHybrid);
  checkRun(run, counter, 50);
  // The session reports its hybrid rendering (dpc-demo's --stats "hybrid_rendering"): one
  // count per propagation frame of the played listener, and the shoebox's one source in one
  // of the late buses.
  CHECK(run.hybrid.on);
  CHECK(run.hybrid.counts.frames == run.status.frames);
  CHECK(run.hybrid.counts.occupiedBuses == 1);
  CHECK(run.hybrid.buses >= 1);
}

// Head-tracked binaural adds the sound field's rotation (per block, crossfaded on a turn) and
// the binaural decoder's partitioned convolutions (MagLS, audio/head_tracked_binaural.h) to the
// audio thread: still no heap call while the head turns and IRs are swapped.
TEST_CASE("LiveSession::render with head-tracked binaural makes no heap calls while turning",
          "[rt]") {
  CountHeapCalls counter;
  const test::LiveRun run = test::driveLiveSession(2000, 10, counter, 0, Rendering::kAuto,
                                                   OutputFormat::kAmbisonicBinaural);
  checkRun(run, counter, 10);
}

// Without FFT wisdom a session with measured plans starts on estimated ones and its planner
// thread swaps the measured ones in while the audio thread renders: the swap is an atomic plan
// pointer, no heap call on the audio thread.
TEST_CASE("LiveSession::render makes no heap calls while its FFT plans are swapped in", "[rt]") {
  CountHeapCalls counter;
  const test::LiveRun run = test::driveLiveSession(2000, 10, counter, 0, Rendering::kAuto,
                                                   OutputFormat::kMono, true);
  checkRun(run, counter, 10);
  CHECK_FALSE(run.plansMeasuredAtStart);
  CHECK(run.plansMeasured);
}

TEST_CASE("A session rendering every source whole reports no hybrid rendering", "[rt]") {
  CountHeapCalls counter;
  const test::LiveRun run = test::driveLiveSession(200, 2, counter, 0, Rendering::kPerSource);
  CHECK_FALSE(run.hybrid.on);
  CHECK(run.hybrid.counts.frames == 0);
}
