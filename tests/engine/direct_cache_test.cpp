// The direct sound kept from frame to frame while nothing it depends on moves
// (engine/direct_cache.h). Oracle: a fresh Simulation, whose first frame computes the direct
// sound (with its edge paths) from scratch for the same source, listener and object poses.
#include <catch2/catch.hpp>
#include <vector>

#include "engine/direct_cache.h"
#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("Direct cache: any moved input is a miss", "[engine]") {
  DirectCache c;
  c.reserve(2);
  const glm::vec3 s{1, 1, 1}, f{1, 0, 0};
  const ListenerSphere l{{4, 1, 1}, 0.5f};
  const std::vector<Pose> poses = {test::kDoorShut};
  c.posesApplied(poses);
  CHECK_FALSE(c.holds(0, s, f, l));  // never computed
  c.computed(0, s, f, l);
  CHECK(c.holds(0, s, f, l));
  CHECK_FALSE(c.holds(1, s, f, l));  // another pair
  CHECK_FALSE(c.holds(0, s + glm::vec3(0.001f, 0, 0), f, l));
  CHECK_FALSE(c.holds(0, s, glm::vec3(0, 0, 1), l));
  CHECK_FALSE(c.holds(0, s, f, ListenerSphere{{4, 1, 1.001f}, 0.5f}));
  CHECK_FALSE(c.holds(0, s, f, ListenerSphere{{4, 1, 1}, 0.4f}));
  c.posesApplied(poses);  // the same poses again
  CHECK(c.holds(0, s, f, l));
  c.posesApplied({test::kDoorOpen});  // an object moved
  CHECK_FALSE(c.holds(0, s, f, l));
}

namespace {

Simulation::SourceResult directAfter(const SceneDesc& scene, const std::vector<Pose>& first,
                                     int framesFirst, const std::vector<Pose>& then) {
  Simulation sim(scene);
  const glm::vec3 listener = scene.listeners[0].position;
  for (int f = 0; f < framesFirst; ++f) {
    FrameInputs in = sim.inputsAt(listener);
    in.objectPoses = first;
    sim.runFrame(in);
  }
  FrameInputs in = sim.inputsAt(listener);
  in.objectPoses = then;
  sim.runFrame(in);
  return sim.result(0);
}

bool sameDirect(const DirectSound& a, const DirectSound& b) {
  bool same = a.visible == b.visible && a.delaySeconds == b.delaySeconds &&
              a.distance == b.distance && a.crossings == b.crossings && a.direction == b.direction;
  for (int k = 0; k < kNumBands; ++k) same = same && a.intensity[k] == b.intensity[k];
  return same;
}

}  // namespace

TEST_CASE("Direct cache: a door that opens after still frames is heard through at once",
          "[engine]") {
  // Two rooms joined by a doorway, source and listener in different rooms: the direct sound
  // is the doorway's edge paths. Three frames with the door shut, then the door taken away
  // (moved 40 m off): the direct sound must be what a fresh simulation computes without the
  // door, bit for bit, and not the shut door's.
  SceneDesc scene = test::twoRooms(DpcWeighting::kEma, 0.5f);
  scene.propagation.raysPerFrame = 256;
  REQUIRE(scene.propagation.diffraction);
  const Pose away{{45.f, 0.f, 3.f}, glm::quat(1, 0, 0, 0)};
  const Simulation::SourceResult opened = directAfter(scene, {test::kDoorShut}, 3, {away});
  const Simulation::SourceResult fresh = directAfter(scene, {away}, 0, {away});
  const Simulation::SourceResult shut = directAfter(scene, {test::kDoorShut}, 3, {test::kDoorShut});
  CHECK(sameDirect(opened.direct, fresh.direct));
  CHECK(opened.diffractionEdges == fresh.diffractionEdges);
  CHECK(opened.direct.intensity.sum() > 0.f);
  CHECK(opened.direct.intensity.sum() > 2.f * shut.direct.intensity.sum());
  // Still frames keep the first frame's direct sound, bit for bit.
  const Simulation::SourceResult first =
      directAfter(scene, {test::kDoorShut}, 0, {test::kDoorShut});
  CHECK(sameDirect(shut.direct, first.direct));
}
