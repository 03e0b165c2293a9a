// Teleports: a source or listener that jumps is heard at its new place at once. Its pairs'
// caches start over at the jump (FrameInputs::sourceRestarts / listenerRestarts), so the first
// response after it is one frame's estimate at the new place, with nothing of the old one.
//
// Oracle: plain path tracing, which keeps nothing between frames. The DPC's first frame after
// a restart reads out one frame's sums divided by 1, the same float operations as path
// tracing's, so the two responses are equal bit for bit (exact paths off: their cache would
// otherwise differ in which sequences it already knows). Without the restart the DPC averages
// the old place into the window, which the second case shows is far from the new place.
#include <catch2/catch.hpp>
#include <vector>

#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

SceneDesc room() {
  SceneDesc s = test::makeShoebox({10, 7, 3}, Bands(0.3f), 0.5f, {2, 2, 1.5f}, {7, 4.5f, 1.6f});
  s.propagation.exactOrder = 0;
  s.propagation.raysPerFrame = 2048;
  return s;
}

/// Runs 8 frames with the source at `before`, then one at `after` (restarting the source's
/// pairs first when `restart`); the last frame's energy response of the pair.
EnergyResponse jump(Estimator estimator, bool restart, Tracing tracing) {
  SceneDesc s = room();
  s.propagation.estimator = estimator;
  s.propagation.tracing = tracing;
  Simulation sim(s);
  const ListenerSphere listener{s.listeners[0].position, s.listeners[0].radius};
  for (int f = 0; f < 8; ++f) sim.runFrame(std::span(&listener, 1), {{1.f, 1.f, 1.f}});
  FrameInputs jumped = Simulation::inputsAt(std::span(&listener, 1), {{6.5f, 4.f, 1.5f}});
  if (restart) jumped.sourceRestarts = {1};
  sim.runFrame(jumped);
  return sim.result(0).energy;
}

double total(const EnergyResponse& e) {
  return double(e.total().sum());
}

}  // namespace

TEST_CASE("After a teleport the response is the new place's, bit for bit", "[engine]") {
  for (const Tracing tracing : {Tracing::kFromSources, Tracing::kFromListeners}) {
    const EnergyResponse fresh = jump(Estimator::kPathTracing, false, tracing);
    const EnergyResponse restarted = jump(Estimator::kDpc, true, tracing);
    REQUIRE(total(fresh) > 0.0);
    REQUIRE(restarted.binCount() == fresh.binCount());
    for (size_t k = 0; k < fresh.binCount(); ++k) CHECK(restarted.bins()[k] == fresh.bins()[k]);
  }
}

TEST_CASE("Without a teleport the cache averages the old place in", "[engine]") {
  const EnergyResponse fresh = jump(Estimator::kPathTracing, false, Tracing::kFromSources);
  const EnergyResponse averaged = jump(Estimator::kDpc, false, Tracing::kFromSources);
  // The old place (1, 1, 1) is far from the listener, the new one 0.9 m away: the window of
  // 15 frames holds 8 old frames and 1 new one, so its early energy is far below the new place's.
  const double early = [](const EnergyResponse& e) {
    double sum = 0.0;
    for (size_t k = 0; k < 20; ++k) sum += double(e.bins()[k].sum());
    return sum;
  }(averaged);
  double freshEarly = 0.0;
  for (size_t k = 0; k < 20; ++k) freshEarly += double(fresh.bins()[k].sum());
  CHECK(early < 0.5 * freshEarly);
}

TEST_CASE("A teleport keyframe holds the old place until its time and marks the jump",
          "[engine]") {
  SceneDesc s = room();
  const auto at = [](double t, glm::vec3 p) {
    Keyframe k;
    k.timeSeconds = t;
    k.position = p;
    return k;
  };
  s.sources[0].trajectory = {at(0.0, {1, 1, 1}), at(1.0, {6, 4, 1.5f}), at(2.0, {8, 5, 1.5f})};
  s.sources[0].trajectory[1].teleport = true;
  WorldState w;
  evaluateWorld(s, 0.5, w);
  CHECK(w.sourcePositions[0] == glm::vec3(1, 1, 1));  // held, not halfway
  CHECK(w.sourceTeleports[0] == 0);
  evaluateWorld(s, 1.0 + 1.0 / 15.0, w);
  CHECK(w.sourceTeleports[0] == 1);
  CHECK(w.sourcePositions[0].x > 6.f);
  evaluateWorld(s, 1.2, w);
  CHECK(w.sourceTeleports[0] == 0);
  // A looping trajectory jumps again every period.
  s.sources[0].trajectoryLoop = true;
  CHECK(teleportBetween(s.sources[0].trajectory, true, 2.9, 3.1));
  CHECK_FALSE(teleportBetween(s.sources[0].trajectory, true, 3.1, 3.8));
}
