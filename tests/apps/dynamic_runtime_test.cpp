// The render pipeline moves sources and objects to scene time t, and host overrides (the
// LiveSession setters' path) replace the trajectories.
#include <catch2/catch.hpp>
#include <cstring>
#include <glm/gtc/quaternion.hpp>
#include <stdexcept>

#include "../engine/test_scenes.h"
#include "runtime/render_pipeline.h"

using namespace dpc;

TEST_CASE("PropagationStage follows source trajectories and host overrides", "[dynamic]") {
  SceneDesc s = test::twoRooms(DpcWeighting::kWindow, 0.f);
  s.propagation.raysPerFrame = 64;
  // Line of sight only: with diffraction the doorway's edges would bring the source back into
  // the direct sound when the panel blocks it.
  s.propagation.diffraction = false;
  Keyframe a, b;
  a.timeSeconds = 0.0, a.position = {1, 1.2f, 1};
  b.timeSeconds = 2.0, b.position = {3, 1.2f, 1};
  s.sources[0].trajectory = {a, b};
  PropagationStage stage(s, s.propagation);
  const glm::vec3 L{4, 1.2f, 1};  // same room as the source: line of sight
  const Orientation o;
  stage.recycle(stage.computeFrame(L, o, 1.0));
  CHECK(stage.simulation().result(0).direct.distance == Approx(2.0).epsilon(1e-5));  // at x = 2
  stage.overrideSource(0, {0.5f, 1.2f, 1});
  stage.recycle(stage.computeFrame(L, o, 1.5));
  CHECK(stage.simulation().result(0).direct.distance == Approx(3.5).epsilon(1e-5));
  // Object override: the door panel (see test_scenes.h) moved between source and listener.
  stage.overrideObject(0, Pose{{3.9f, 0.f, 0.5f}, glm::quat(1, 0, 0, 0)});
  stage.recycle(stage.computeFrame(L, o, 1.6));
  CHECK_FALSE(stage.simulation().result(0).direct.visible);
  stage.overrideObject(0, test::kDoorOpen);
  stage.recycle(stage.computeFrame(L, o, 1.7));
  CHECK(stage.simulation().result(0).direct.visible);
}

TEST_CASE("PropagationStage takes a whole world state; two listeners at one place agree",
          "[dynamic]") {
  SceneDesc s = test::twoRooms(DpcWeighting::kWindow, 0.f);
  s.propagation.raysPerFrame = 256;
  ListenerDesc a = s.listener, b = s.listener;
  a.name = "a", b.name = "b";
  s.listeners = {a, b};
  WorldState w;
  evaluateWorld(s, 0.0, w);
  REQUIRE(w.listenerPositions.size() == 2);
  // Same seed, same place, same frame index: the same response bit for bit.
  PropagationStage one(s, s.propagation), two(s, s.propagation);
  one.recycle(one.computeFrame(w, 0));
  two.recycle(two.computeFrame(w, 1));
  CHECK(one.simulation().result(0).energy.total()[3] > 0.f);
  CHECK(std::memcmp(one.simulation().result(0).energy.bins().data(),
                    two.simulation().result(0).energy.bins().data(),
                    one.simulation().result(0).energy.binCount() * sizeof(Bands)) == 0);
  CHECK_THROWS_AS(one.computeFrame(w, 2), std::out_of_range);
}
