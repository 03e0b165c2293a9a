// SessionCounters and FrameTotals (runtime/session_stats.h): counts as documented.
#include "runtime/session_stats.h"

#include <catch2/catch.hpp>

using namespace dpc;

TEST_CASE("SessionCounters: rays, frames, blocks and callbacks as counted", "[stats]") {
  SessionCounters c(1000, 400);  // scene rays, the controller's floor
  c.started(1'000'000'000);
  SessionStatus st;
  c.read(st);
  CHECK(st.frames == 0);
  CHECK(st.raysPerFrameMin == 0);
  CHECK(st.raysPerFrameScene == 1000);
  c.raysTraced(1000);
  c.raysTraced(400);
  c.raysTraced(800);
  FrameTotals t;
  t.rays = 2400;
  t.cacheEntries = 10;
  t.cacheCoarseEntries = 5;
  t.droppedEnergyFraction = 0.25;
  t.chainsLeftOut = 7;
  c.frameDone(t, 12.5);
  c.blockDone(true, 1, 3.0);
  c.blockDone(false, 2, -1.0);  // no IR age: the last one stays
  c.lateCallback(3'500'000'000, 4'000'000);  // 2.5 s after the start, 4 ms long
  c.rejectedCallback();
  c.read(st);
  CHECK(st.raysPerFrame == 800);
  CHECK(st.raysPerFrameMin == 400);
  CHECK(st.reducedFrames == 2);
  CHECK(st.raysPerFrameFloor == 400);
  CHECK(st.floorFrames == 1);  // the 400-ray frame
  // Quantiles of 1000, 400, 800: the 5th percentile is the 400-ray frame, the median the 800
  // one (each the upper edge of its 6.25 % histogram bin).
  CHECK(st.raysPerFrameP5 >= 400);
  CHECK(st.raysPerFrameP5 <= 425);
  CHECK(st.raysPerFrameMedian >= 800);
  CHECK(st.raysPerFrameMedian <= 850);
  CHECK(st.frames == 1);
  CHECK(st.frameMs == 12.5);
  CHECK(st.cacheEntries == 15);
  CHECK(st.droppedEnergyFraction == 0.25);
  CHECK(st.chainsLeftOut == 7);
  CHECK(st.blocks == 2);
  CHECK(st.nanBlocks == 1);
  CHECK(st.irsApplied == 2);
  CHECK(st.irAgeMs == 3.0);
  CHECK(st.lateCallbacks == 1);
  CHECK(st.lateCallbackAtSeconds[0] == Approx(2.5));
  CHECK(st.lateCallbackMs[0] == Approx(4.0));
  CHECK(st.lateCallbackMs[1] == 0.0);
  CHECK(st.rejectedCallbacks == 1);
  // Beyond the kept ones only the count grows.
  for (int i = 0; i < SessionStatus::kLateCallbacksKept + 3; ++i)
    c.lateCallback(2'000'000'000 + i, 5'000'000 + i);
  c.read(st);
  CHECK(st.lateCallbacks == SessionStatus::kLateCallbacksKept + 4);
  CHECK(st.lateCallbackMs[0] == Approx(4.0));
  CHECK(st.lateCallbackAtSeconds[1] == Approx(1.0));
  CHECK(st.lateCallbackMs.back() == Approx(5.0 + (SessionStatus::kLateCallbacksKept - 2) * 1e-6));
}

TEST_CASE("FrameTotals: sums, largest shares, and the energy beyond the IR length", "[stats]") {
  Simulation::SourceResult a, b;
  a.energy = EnergyResponse(0.01, 0.001);  // 10 bins
  b.energy = EnergyResponse(0.01, 0.001);
  a.energy.add(0.002, Bands(3.f));
  a.energy.add(0.5, Bands(1.f));  // beyond the length: dropped
  b.energy.add(0.002, Bands(1.f));
  a.trace.rays = 100;
  b.trace.rays = 50;
  a.cacheEntries = 4;
  b.cacheEntries = 6;
  a.cacheCoarseEnergyFraction = 0.1;
  b.cacheCoarseEnergyFraction = 0.3;
  a.direct.chainsLeftOut = 2;
  b.direct.chainsLeftOut = 3;
  FrameTotals t;
  t.add(a);
  t.add(b);
  CHECK(t.rays == 150);
  CHECK(t.cacheEntries == 10);
  CHECK(t.cacheCoarseEnergyFraction == 0.3);
  CHECK(t.droppedEnergyFraction == Approx(0.25));  // a: 1 of 4 dropped, b: none
  CHECK(t.chainsLeftOut == 5);
}

TEST_CASE("SessionCounters: the max_order cut's peak outlives the frame that set it", "[stats]") {
  // A live warning reads the counters once a second; a single frame cut short in between must
  // still be seen. Last frame's share follows each frame, the peak only rises.
  SessionCounters c(1000, 400);
  SessionStatus st;
  FrameTotals t;
  for (double share : {1e-6, 3e-3, 2e-5}) {
    t.maxOrderEnergyFraction = share;
    c.frameDone(t, 10.0);
  }
  c.read(st);
  CHECK(st.maxOrderEnergyFraction == 2e-5);
  CHECK(st.maxOrderEnergyFractionPeak == 3e-3);
}

TEST_CASE("maxOrderWarning: the order, the share in percent and dB, the advice", "[stats]") {
  // 1e-3 of the emitted energy is 0.1 % and 10 log10(1e-3) = -30 dB.
  const std::string known = maxOrderWarning(12, 1e-3);
  CHECK(known.rfind("propagation.max_order: rays ended at order 12 still carried 0.1 % ", 0) == 0);
  CHECK(known.find("(-30 dB, largest band)") != std::string::npos);
  CHECK_THAT(known, Catch::EndsWith("; raise max_order"));
  CHECK(maxOrderWarning(0, 1e-3).find("at their last order still") != std::string::npos);
}
