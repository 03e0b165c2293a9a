// Many sources traced from one listener (PropagationSettings::tracing): every source keeps its
// own direct sound, occlusion and reverberant energy, and one cache pool bounds all pairs'
// memory without changing their energy.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <vector>

#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

double total(const EnergyResponse& e) {
  return double(e.total().sum());
}

}  // namespace

// Oracle: the free-field direct sound, delay r / c and intensity 1 / (4 pi r^2) (times the air
// attenuation, here off), for each of 64 sources at its own distance.
TEST_CASE("64 sources in free field: each direct sound at r/c and 1/(4 pi r^2)", "[engine]") {
  SceneDesc s = test::makeShoebox({200, 200, 200}, Bands(1.f), 1.f, {100, 100, 100},
                                  {100, 100, 100});
  s.propagation.airAbsorption = false;
  s.propagation.raysPerFrame = 256;
  s.propagation.tracing = Tracing::kAuto;  // 64 sources, 1 listener: from the listener
  std::vector<glm::vec3> sources;
  for (int i = 0; i < 64; ++i) {
    const float a = 0.37f * float(i), r = 2.f + 0.5f * float(i);
    sources.push_back({100.f + r * std::cos(a), 100.f + 0.3f * float(i % 7), 100.f + r * std::sin(a)});
    SourceDesc d = s.sources[0];
    d.position = sources.back();
    if (i > 0) s.sources.push_back(d);
  }
  s.sources[0].position = sources[0];
  Simulation sim(s);
  const ListenerSphere listener{{100, 100, 100}, 0.5f};
  sim.runFrame(std::span(&listener, 1), sources);
  REQUIRE(sim.sourceCount() == 64);
  for (size_t i = 0; i < 64; ++i) {
    const double r = glm::length(sources[i] - listener.position);
    const DirectSound& d = sim.result(i).direct;
    CHECK(d.visible);
    CHECK(d.delaySeconds == Approx(r / 343.0).epsilon(1e-5));
    CHECK(d.intensity[4] == Approx(1.0 / (4.0 * std::numbers::pi * r * r)).epsilon(1e-5));
  }
  CHECK(sim.frameTrace().rays == 256);  // one pass, whatever the number of sources
}

// Oracle: geometry (the wall blocks the line of sight) and reciprocity: the occluded source's
// reverberant energy through the room equals the source-based tracing's within Monte Carlo
// error (4 standard errors of the per-frame totals, as in reciprocity_test).
TEST_CASE("A source behind a wall is occluded and still reverberant", "[engine][statistics]") {
  SceneDesc s = test::makeShoebox({10, 4, 8}, Bands(0.2f), 0.5f, {2, 1.5f, 2}, {8, 1.6f, 6});
  // A free-standing wall (x 3..7, full height, at z = 4): the first source is behind it.
  test::addPanel(s.mesh, {3, 0, 4}, {4, 0, 0}, {0, 4, 0}, 0);
  s.sources.push_back(s.sources[0]);
  s.sources[0].position = {5, 1.5f, 2};  // behind the wall, seen from the listener at z = 6
  s.sources[1].position = {8, 1.5f, 2};  // beside it, in sight
  s.propagation.estimator = Estimator::kPathTracing;
  s.propagation.irLength = 0.6f;
  s.propagation.diffraction = false;  // the line of sight alone (edge paths would make it audible)
  auto run = [&](Tracing t, uint64_t seed, double& mean, double& sem, bool& visible) {
    s.propagation.tracing = t;
    s.propagation.seed = seed;
    Simulation sim(s);
    double sum = 0.0, sum2 = 0.0;
    constexpr int kFrames = 30;
    for (int f = 0; f < kFrames; ++f) {
      sim.runFrame(s.listeners[0].position);
      const double e = total(sim.result(0).energy);
      sum += e;
      sum2 += e * e;
    }
    visible = sim.result(0).direct.visible;
    CHECK(sim.result(1).direct.visible);
    mean = sum / kFrames;
    sem = std::sqrt(std::max(0.0, sum2 / kFrames - mean * mean) / (kFrames - 1));
  };
  double mf = 0, sf = 0, mb = 0, sb = 0;
  bool vf = true, vb = true;
  run(Tracing::kFromSources, 3, mf, sf, vf);
  run(Tracing::kFromListeners, 4, mb, sb, vb);
  CHECK_FALSE(vf);
  CHECK_FALSE(vb);
  REQUIRE(mf > 0.0);
  INFO("from sources " << mf << " +- " << sf << ", from the listener " << mb << " +- " << sb);
  CHECK(std::abs(mf - mb) <= 4.0 * std::hypot(sf, sb));
}

// Oracle: the merge is linear in the cache's state, so a pool too small for the pairs' paths
// changes each response's energy only by float rounding (relative 1e-4 over thousands of
// float additions of positive terms), while the refusals and merges are counted.
TEST_CASE("A tiny cache pool keeps every pair's energy and reports its merges", "[engine]") {
  SceneDesc s = test::makeShoebox({10, 7, 3}, Bands(0.1f), 0.8f, {2, 2, 1.5f}, {7, 4.5f, 1.6f});
  for (int i = 1; i < 6; ++i) {
    s.sources.push_back(s.sources[0]);
    s.sources.back().position = {1.f + 1.5f * float(i), 1.5f + 0.7f * float(i % 3), 1.2f};
  }
  s.propagation.exactOrder = 0;
  s.propagation.raysPerFrame = 4096;
  SceneDesc tiny = s;
  tiny.propagation.cachePoolMb = 1.f;  // below the six pairs' first tables: every growth refused
  Simulation big(s), small(tiny);
  for (int f = 0; f < 12; ++f) {
    big.runFrame(s.listeners[0].position);
    small.runFrame(s.listeners[0].position);
  }
  uint64_t refused = 0, merged = 0;
  for (size_t i = 0; i < s.sources.size(); ++i) {
    CHECK(total(small.result(i).energy) ==
          Approx(total(big.result(i).energy)).epsilon(1e-4));
    CHECK(big.result(i).cachePoolRefusals == 0);
    refused += small.result(i).cachePoolRefusals;
    merged += small.result(i).cacheMergedEntries;
  }
  CHECK(refused > 0);
  CHECK(merged > 0);
  CHECK(small.result(0).cachePoolUsedBytes <= big.result(0).cachePoolUsedBytes);
}
