// The render pipeline traces the world state it is given: sources and objects at scene time t,
// or where a host placed them (the LiveSession setters' path, assembled by HostPoses).
#include <catch2/catch.hpp>
#include <array>
#include <cstring>
#include <glm/gtc/quaternion.hpp>
#include <stdexcept>

#include "scene/trajectory.h"
#include "testing/test_scenes.h"
#include "runtime/host_poses.h"
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
  s.listeners[0].position = {4, 1.2f, 1};  // same room as the source: line of sight
  const auto scene = test::shared(s);
  PropagationStage stage(scene, s.propagation);
  // The live session's path: trajectories at t, then the host's overrides (HostPoses).
  HostPoses host(scene, 0);
  WorldState w;
  size_t played = 0;
  auto frame = [&](double t) {
    host.setListenerPose(0, s.listeners[0].position, 0.f, t, 0.f);
    host.assemble(w, played);
    stage.traceWorld(w);
    stage.synthesizeIrs(played);
  };
  frame(1.0);
  CHECK(stage.simulation().result(0).direct.distance == Approx(2.0).epsilon(1e-5));  // at x = 2
  CHECK(host.setSourcePosition(0, {0.5f, 1.2f, 1}));
  frame(1.5);
  CHECK(stage.simulation().result(0).direct.distance == Approx(3.5).epsilon(1e-5));
  // Object override: the door panel (see test_scenes.h) moved between source and listener.
  const float shut[4] = {0.f, 0.f, 0.f, 1.f};
  CHECK(host.setObjectPose(0, {3.9f, 0.f, 0.5f}, shut));
  frame(1.6);
  CHECK_FALSE(stage.simulation().result(0).direct.visible);
  const glm::quat q = test::kDoorOpen.rotation;
  const float open[4] = {q.x, q.y, q.z, q.w};
  CHECK(host.setObjectPose(0, test::kDoorOpen.position, open));
  frame(1.7);
  CHECK(stage.simulation().result(0).direct.visible);
  CHECK_FALSE(host.setSourcePosition(1, {0.f, 0.f, 0.f}));
  CHECK_FALSE(host.setObjectPose(0, {0.f, 0.f, 0.f}, std::array<float, 4>{}.data()));
}

TEST_CASE("PropagationStage takes a whole world state, two listeners at one place agree",
          "[dynamic]") {
  SceneDesc s = test::twoRooms(DpcWeighting::kWindow, 0.f);
  // Enough rays that every band reaches the listener in one frame (a ray off the door leaf
  // goes on with one band, engine/reflection_scattering.h).
  s.propagation.raysPerFrame = 2048;
  ListenerDesc a = s.listeners[0], b = s.listeners[0];
  a.name = "a", b.name = "b";
  s.listeners = {a, b};
  WorldState w;
  evaluateWorld(s, 0.0, w);
  REQUIRE(w.listenerPositions.size() == 2);
  // Same seed, same place, same frame: the two listeners' responses agree bit for bit.
  PropagationStage stage(test::shared(s), s.propagation);
  stage.traceWorld(w);
  stage.synthesizeIrs(0);
  stage.synthesizeIrs(1);
  const EnergyResponse& e0 = stage.simulation().result(0, 0).energy;
  const EnergyResponse& e1 = stage.simulation().result(0, 1).energy;
  CHECK(e0.total()[3] > 0.f);
  CHECK(std::memcmp(e0.bins().data(), e1.bins().data(), e0.binCount() * sizeof(Bands)) == 0);
  CHECK(stage.lastIrs(0) == stage.lastIrs(1));
  CHECK_THROWS_AS(stage.synthesizeIrs(2), std::out_of_range);
  w.sourcePositions.clear();
  CHECK_THROWS_AS(stage.traceWorld(w), std::invalid_argument);
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
  ListenerDesc a = s.listeners[0], b = s.listeners[0];
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
    const OfflineResult all = renderOffline(test::shared(s), s.propagation, test::shared(dry), opt);
    REQUIRE(all.listeners.size() == 2);
    CHECK(all.listeners[1].name == "b");
    opt.allListeners = false;
    for (size_t l = 0; l < 2; ++l) {
      opt.listener = l;
      const OfflineResult alone = renderOffline(test::shared(s), s.propagation, test::shared(dry), opt);
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
  DrySignals dry;
  dry.samples = {std::vector<float>(4800, 0.f)};
  dry.loop = {1};
  LiveSession::Options o;
  o.deviceChannels = 1;
  o.listener = 1;  // --listener b
  LiveSession live(test::shared(s), s.propagation, test::shared(dry), o);
  CHECK(live.listenerCount() == 2);
  CHECK(live.playedListener() == 1);
  CHECK(live.setListenerPose(0, {7.f, 1.2f, 2.f}, 0.f, 0.0));
  CHECK_FALSE(live.setListenerPose(2, {7.f, 1.2f, 2.f}, 0.f, 0.0));
  CHECK(live.selectListener(0));
  CHECK(live.playedListener() == 0);
  CHECK_FALSE(live.selectListener(2));
  CHECK(live.playedListener() == 0);
}
