// Work and memory estimate (engine/workload): the expected reflection order against the
// segments the propagator really traces, linear scaling, and the refusals with their numbers.
#include "engine/workload.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "common/input_error.h"
#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "engine/path_cache.h"
#include "engine/propagation.h"
#include "testing/test_util.h"
#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("expected reflection order matches the segments traced in a diffuse shoebox",
          "[workload]") {
  // alpha = 0.2 in every band, no air absorption: energy after n reflections is 0.8^n, the
  // roulette threshold 1e-6 is reached at n = ln(1e-6) / ln(0.8) = 61.9.
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.2f), 0.5f, {2, 1.5f, 2}, {7, 1.6f, 5});
  PropagationSettings ps;
  ps.maxOrder = 1000;
  ps.raysPerFrame = 2000;
  ps.airAbsorption = false;
  const WorkloadEstimate e = estimateWorkload(scene, ps, 1, 10.0);
  Geometry g(scene.mesh, scene.materials, 0.5f);
  EmbreeTracer tracer(scene.mesh);
  Propagator prop(g, tracer, ps);
  FrameGroups groups;
  const ListenerSphere listener{{7, 1.6f, 5}, 0.5f};
  const TraceStats t =
      prop.traceFrame(test::traceRequest(ps, 0, 0, {2, 1.5f, 2}, std::span(&listener, 1)), groups);
  const double perRay = double(t.segments) / ps.raysPerFrame;
  // The estimate is an upper estimate by design (survivors' share rounded up to 10 %); the
  // traced mean lies within 15 % below it (Monte Carlo error of 2000 rays' roulette: ~1 %).
  CHECK(perRay <= e.expectedOrder + 1.0);
  CHECK(perRay >= 0.85 * (e.expectedOrder + 1.0));
  CHECK(e.segmentsPerFrame == Approx(ps.raysPerFrame * (e.expectedOrder + 1.0)));
  CHECK(e.segmentsTotal == Approx(e.segmentsPerFrame * ps.frameRate * 10.0));
  // A low max_order caps the order.
  ps.maxOrder = 5;
  CHECK(estimateWorkload(scene, ps, 1, 10.0).expectedOrder == 5.0);
}

TEST_CASE("work and memory that cannot finish or fit are refused, naming the setting",
          "[workload]") {
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.5f, {2, 1.5f, 2}, {7, 1.6f, 5});
  scene.path = "room.json";
  PropagationSettings ps;
  const double memory = 2e9;
  // The shoebox defaults for a minute: fine, no warning.
  CHECK(checkWorkload(scene, ps, estimateWorkload(scene, ps, 1, 60.0), memory).empty());
  // 1e8 rays x order 10000: one frame alone is beyond reach.
  ps.raysPerFrame = 100'000'000;
  ps.maxOrder = 10'000;
  CHECK_THROWS_WITH(checkWorkload(scene, ps, estimateWorkload(scene, ps, 1, 1.0), memory),
                    Catch::StartsWith("room.json: propagation.rays_per_frame: ") &&
                        Catch::Contains("ray segments per frame"));
  // A day at 1e6 rays: refused on the total; an hour at 2e4 rays: warned.
  ps.raysPerFrame = 1'000'000;
  CHECK_THROWS_WITH(checkWorkload(scene, ps, estimateWorkload(scene, ps, 1, 86400.0), memory),
                    Catch::Contains("the duration"));
  ps.raysPerFrame = 20'000;
  const auto w = checkWorkload(scene, ps, estimateWorkload(scene, ps, 1, 3600.0), memory);
  REQUIRE(w.size() == 1);
  CHECK_THAT(w[0], Catch::Contains("ray segments to trace"));
  // 60 s IRs at 192 kHz binaural: 60 x 192000 x 2 x 160 B = 3.7 GB.
  ps = PropagationSettings{};
  ps.irLength = 60.f;
  scene.audio.sampleRate = 192000;
  const WorkloadEstimate big = estimateWorkload(scene, ps, 2, 1.0);
  CHECK(big.irBytes == Approx(60.0 * 192000 * 2 * kIrBytesPerSample));
  CHECK_THROWS_WITH(
      checkWorkload(scene, ps, big, memory),
      Catch::StartsWith("room.json: propagation.ir_length: ") && Catch::Contains("GB"));
  CHECK_NOTHROW(checkWorkload(scene, ps, big, 8e9));
}

TEST_CASE("the path caches' budgets count in the memory estimate, and the time is estimated",
          "[workload]") {
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.5f, {2, 1.5f, 2}, {7, 1.6f, 5});
  scene.path = "room.json";
  scene.sources.push_back(scene.sources.front());
  scene.sources.back().name = "second";
  PropagationSettings ps;
  // The documented maximum, 16384 MiB per source-listener pair, 2 sources: 34.4 GB.
  ps.cacheMemoryMb = 16384.f;
  ps.cachePoolMb = 65536.f;  // the pool's maximum: the pairs' budgets bind
  const WorkloadEstimate e = estimateWorkload(scene, ps, 2, 10.0);
  CHECK(e.cacheBytes == Approx(2.0 * 16384.0 * 1048576.0));
  CHECK_THROWS_WITH(
      checkWorkload(scene, ps, e, 8e9),
      Catch::StartsWith("room.json: propagation.cache_memory_mb: ") && Catch::Contains("34.4 GB"));
  // Eight sources at the same budgets: the pool binds (64 GiB, 68.7 GB) and is named.
  SceneDesc eight = scene;
  eight.sources.resize(8, scene.sources.front());
  const WorkloadEstimate e8 = estimateWorkload(eight, ps, 2, 10.0);
  CHECK(e8.cacheBytes == Approx(65536.0 * 1048576.0));
  CHECK_THROWS_WITH(
      checkWorkload(eight, ps, e8, 8e9),
      Catch::StartsWith("room.json: propagation.cache_pool_mb: ") && Catch::Contains("68.7 GB"));
  // A budget that fits: accepted.
  ps.cacheMemoryMb = 64.f;
  CHECK_NOTHROW(checkWorkload(scene, ps, estimateWorkload(scene, ps, 2, 10.0), 8e9));
  // The time: segments at the nominal rate, in the warning.
  ps.raysPerFrame = 20'000;
  const WorkloadEstimate hour = estimateWorkload(scene, ps, 1, 3600.0);
  CHECK(hour.expectedSeconds == Approx(hour.segmentsTotal / kNominalSegmentsPerSecond));
  const auto w = checkWorkload(scene, ps, hour, 8e9);
  REQUIRE(w.size() == 1);
  CHECK_THAT(w[0], Catch::Contains("min (at 2e+07 segments/s)"));
}

TEST_CASE("the automatic path cache pool grows with the pairs and the paths they keep",
          "[workload]") {
  PropagationSettings ps;  // the defaults: auto, 4096 rays, tau 1 s, 15 frames/s
  REQUIRE(ps.cachePoolMb == kCachePoolAuto);
  // Up to 32 pairs the floor holds; from there 4 MB per pair (the measured 1.8-2.0 MB of
  // tables per pair, doubled by the tables' growth in powers of two).
  CHECK(cachePoolMbFor(ps, 1) == Approx(std::min(kAutoPoolMinMb, 64.0)));  // its own 64 MB
  CHECK(cachePoolMbFor(ps, 16) == Approx(kAutoPoolMinMb));
  CHECK(cachePoolMbFor(ps, 64) == Approx(64 * kAutoPoolPerPairMb));
  CHECK(cachePoolMbFor(ps, 256) ==
        Approx(std::min(256 * kAutoPoolPerPairMb, 0.25 * plannableMemoryBytes() / 1048576.0)));
  // Twice the rays keep twice the paths; a quarter of the window, a quarter (floor at 1).
  ps.raysPerFrame = 8192;
  CHECK(cachePoolMbFor(ps, 64) == Approx(128 * kAutoPoolPerPairMb));
  ps.raysPerFrame = 4096;
  ps.cacheTau = 0.25f;
  CHECK(cachePoolMbFor(ps, 64) == Approx(64 * kAutoPoolPerPairMb));
  // No pair grows past its own budget, so neither does the pool.
  ps.cacheTau = 1.f;
  ps.cacheMemoryMb = 2.f;
  CHECK(cachePoolMbFor(ps, 64) == Approx(128.0));
  // A value given is the budget.
  ps.cachePoolMb = 32.f;
  CHECK(cachePoolMbFor(ps, 256) == 32.0);
}

TEST_CASE("the automatic pool counts in the memory estimate", "[workload]") {
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.5f, {2, 1.5f, 2}, {7, 1.6f, 5});
  scene.sources.resize(64, scene.sources.front());
  PropagationSettings ps;
  const WorkloadEstimate e = estimateWorkload(scene, ps, 1, 10.0);
  CHECK(e.cacheBytes == Approx(cachePoolMbFor(ps, 64) * 1048576.0));
}
