// The live pipeline (control, propagation and audio threads, SPSC queues, seqlock pose,
// recorder ring) under ThreadSanitizer: scripts/tsan.sh builds this without the interposing
// allocator and fails on any reported race.
#include <catch2/catch.hpp>

#include "live_driver.h"

using namespace dpc;

namespace {
struct Nothing {
  void begin() {}
  void end() {}
};
}  // namespace

TEST_CASE("Live pipeline threads under ThreadSanitizer", "[tsan]") {
  Nothing none;
  const int blocks = 1500;
  // One tracing thread: Debian's TBB is not instrumented, so the hand-back of chunks traced by
  // TBB workers to the propagation thread is invisible to TSan and reported as a race on
  // their memory (seen under load). This test is about dpc's own threads and queues.
  const uint64_t swaps = 30;  // swaps must happen while the threads race
  const test::LiveRun run = test::driveLiveSession(blocks, swaps, none, 1);
  INFO("blocks " << run.status.blocks << ", IRs applied " << run.status.irsApplied);
  CHECK(run.status.blocks >= uint64_t(blocks));
  CHECK(run.status.irsApplied >= swaps);
  CHECK(run.finite);
  CHECK(run.status.nanBlocks == 0);
  CHECK(run.recordedFrames == size_t(run.status.blocks) * 128);  // the recorder lost nothing
}

// The same threads plus the planner's, which swaps measured FFT plans in while the audio thread
// renders with them (ConvolverLayout::measurePlans).
TEST_CASE("Live pipeline threads under ThreadSanitizer, FFT plans swapped in while playing",
          "[tsan]") {
  Nothing none;
  const test::LiveRun run =
      test::driveLiveSession(1500, 10, none, 1, Rendering::kAuto, OutputFormat::kMono, true);
  CHECK_FALSE(run.plansMeasuredAtStart);
  CHECK(run.plansMeasured);
  CHECK(run.finite);
  CHECK(run.status.nanBlocks == 0);
}
