// The render pipeline moves sources and objects to scene time t, and host overrides (the
// LiveSession setters' path) replace the trajectories.
#include <catch2/catch.hpp>
#include <cstring>
#include <glm/gtc/quaternion.hpp>
#include <stdexcept>

#include "testing/test_scenes.h"
#include "runtime/live_session.h"
#include "runtime/offline_renderer.h"
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

TEST_CASE("PropagationStage takes a whole world state, two listeners at one place agree",
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

namespace {

/// The door scene with two listeners, a in room B (the scene's) and b in room A.
SceneDesc twoListenerScene(Estimator estimator) {
  SceneDesc s = test::twoRooms(DpcWeighting::kWindow, 0.3f);
  s.propagation.estimator = estimator;
  s.propagation.raysPerFrame = 256;
  s.propagation.irLength = 0.5f;
  s.objects[0].trajectory[0].position = test::kDoorOpen.position;
  s.objects[0].trajectory[0].rotation = test::kDoorOpen.rotation;
  ListenerDesc a = s.listener, b = s.listener;
  a.name = "a", b.name = "b";
  b.position = {3.5f, 1.2f, 2.f};
  b.radius = 0.4f;
  s.listeners = {a, b};
  return s;
}

}  // namespace

TEST_CASE("Offline: all listeners from one propagation run equal each listener rendered alone",
          "[dynamic][listeners]") {
  // Same seed: one pass over both listeners performs, for each, the float operations of
  // tracing it alone (tests/engine/dynamic_test.cpp), so the outputs are bit-identical.
  for (Estimator est : {Estimator::kPathTracing, Estimator::kDpc}) {
    SceneDesc s = twoListenerScene(est);
    DrySignals dry;
    dry.samples = {std::vector<float>(4800, 0.f)};
    for (size_t n = 0; n < 4800; n += 480) dry.samples[0][n] = 1.f;  // clicks every 10 ms
    dry.loop = {0};
    OfflineOptions opt;
    opt.durationSeconds = 0.6;
    opt.allListeners = true;
    const OfflineResult all = renderOffline(s, s.propagation, dry, opt);
    REQUIRE(all.listeners.size() == 2);
    CHECK(all.listeners[1].name == "b");
    opt.allListeners = false;
    for (size_t l = 0; l < 2; ++l) {
      s.listener = s.listeners[l];
      const OfflineResult alone = renderOffline(s, s.propagation, dry, opt);
      REQUIRE(alone.listeners.size() == 1);
      CHECK(alone.listeners[0].output.channels == all.listeners[l].output.channels);
      CHECK(alone.listeners[0].lastIrs == all.listeners[l].lastIrs);
      // One propagation run: the same rays (and Embree segments) as one listener alone.
      CHECK(alone.totals.segments == all.totals.segments);
    }
    double energy = 0.0;
    for (float x : all.listeners[1].output.channels[0]) energy += double(x) * x;
    CHECK(energy > 0.0);
  }
}

TEST_CASE("LiveSession: listener poses by index and the played listener", "[dynamic][listeners]") {
  SceneDesc s = twoListenerScene(Estimator::kDpc);
  s.listener = s.listeners[1];  // --listener b
  DrySignals dry;
  dry.samples = {std::vector<float>(4800, 0.f)};
  dry.loop = {1};
  LiveSession::Options o;
  o.deviceChannels = 1;
  LiveSession live(s, s.propagation, dry, o);
  CHECK(live.listenerCount() == 2);
  CHECK(live.playedListener() == 1);
  CHECK(live.setListenerPose(0, {7.f, 1.2f, 2.f}, 0.f, 0.0));
  CHECK_FALSE(live.setListenerPose(2, {7.f, 1.2f, 2.f}, 0.f, 0.0));
  CHECK(live.selectListener(0));
  CHECK(live.playedListener() == 0);
  CHECK_FALSE(live.selectListener(2));
  CHECK(live.playedListener() == 0);
}
