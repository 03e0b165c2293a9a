// HostPoses (runtime/host_poses.h): the world state of a frame is the trajectories at the
// played listener's scene time, then the host's overrides.
#include "runtime/host_poses.h"

#include <catch2/catch.hpp>
#include <cfloat>
#include <cmath>

#include "runtime/pose_sync.h"
#include "scene/limits.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("HostPoses: trajectories at the played listener's time, then host overrides", "[poses]") {
  SceneDesc s = test::makeShoebox({6, 3, 4}, Bands(0.3f), 0.5f, {1, 1.5f, 1}, {4, 1.5f, 3});
  Keyframe a, b;
  a.timeSeconds = 0.0, a.position = {1, 1.5f, 1};
  b.timeSeconds = 2.0, b.position = {3, 1.5f, 1};
  s.sources[0].trajectory = {a, b};
  ListenerDesc second = s.listeners[0];
  second.name = "second";
  second.position = {5, 1.5f, 3};
  s.listeners.push_back(second);
  HostPoses host(test::shared(s), 1);
  CHECK(host.listenerCount() == 2);
  CHECK(host.played() == 1);

  WorldState w;
  size_t played = 0;
  ListenerPose pose = host.assemble(w, played);
  CHECK(played == 1);
  CHECK(pose.sceneSeconds == 0.0);
  CHECK(w.listenerPositions[0] == s.listeners[0].position);  // where the scene puts them
  CHECK(w.listenerPositions[1] == second.position);
  CHECK(w.sourcePositions[0] == a.position);

  CHECK(host.setListenerPose(1, {2, 1.5f, 2}, 0.5f, 1.0, 0.f));
  host.assemble(w, played);
  CHECK(w.timeSeconds == 1.0);
  CHECK(w.listenerPositions[1] == glm::vec3(2, 1.5f, 2));
  CHECK(w.listenerOrientations[1].yawRadians == 0.5f);
  CHECK(w.sourcePositions[0].x == Approx(2.0));  // trajectory at t = 1

  CHECK(host.setSourcePosition(0, {5, 1, 1}));
  host.assemble(w, played);
  CHECK(w.sourcePositions[0] == glm::vec3(5, 1, 1));  // the override wins from now on

  CHECK(host.select(0));
  host.assemble(w, played);
  CHECK(played == 0);
  CHECK(w.timeSeconds == 0.0);  // listener 0's pose is still the one at t = 0
  CHECK_FALSE(host.select(2));
  CHECK_FALSE(host.setListenerPose(2, {0, 0, 0}, 0.f, 0.0, 0.f));
  CHECK_FALSE(host.setSourcePosition(1, {0, 0, 0}));
  const float zero[4] = {0, 0, 0, 0};
  CHECK_FALSE(host.setObjectPose(0, {0, 0, 0}, zero));  // no objects in the scene
}

TEST_CASE("HostPoses: a coordinate beyond the scene's limit is refused and changes nothing",
          "[poses][limits]") {
  const SceneDesc s = test::makeShoebox({6, 3, 4}, Bands(0.3f), 0.5f, {1, 1.5f, 1}, {4, 1.5f, 3});
  HostPoses host(test::shared(s), 0);
  const float bound = float(limitOf("position").max);
  CHECK(host.setSourcePosition(0, {bound, -bound, 1}));
  CHECK(host.setListenerPose(0, {-bound, bound, 1}, 0.f, 0.0, 0.f));
  for (const float bad : {std::nextafter(bound, 2 * bound), 1e20f, -FLT_MAX, NAN, INFINITY}) {
    INFO(bad);
    CHECK_FALSE(host.setSourcePosition(0, {1, bad, 1}));
    CHECK_FALSE(host.setListenerPose(0, {1, 1, bad}, 0.f, 0.0, 0.f));
  }
  CHECK_FALSE(host.setListenerPose(0, {1, 1, 1}, NAN, 0.0, 0.f));
  CHECK_FALSE(host.setListenerPose(0, {1, 1, 1}, 0.f, 0.0, INFINITY));
  WorldState w;
  size_t played = 0;
  host.assemble(w, played);
  CHECK(w.sourcePositions[0] == glm::vec3(bound, -bound, 1));  // the last accepted ones
  CHECK(w.listenerPositions[0] == glm::vec3(-bound, bound, 1));
}

TEST_CASE("HostPoses: each pose carries the host's publication interval", "[poses]") {
  SceneDesc s = test::makeShoebox({6, 3, 4}, Bands(0.3f), 0.5f, {1, 1.5f, 1}, {4, 1.5f, 3});
  HostPoses host(test::shared(s), 0);
  ListenerPose first, second;
  REQUIRE(host.tryListenerPose(0, first));
  CHECK(first.intervalNs == 0);  // the scene's start pose: no stream yet
  REQUIRE(host.setListenerPose(0, {2, 1.5f, 2}, 0.f, 0.1, 0.f));
  REQUIRE(host.tryListenerPose(0, second));
  CHECK(second.intervalNs == second.publishedNs - first.publishedNs);
  CHECK(second.intervalNs >= 0);
  // Later gaps move it by a quarter of their difference from it: a moving average.
  ListenerPose third;
  REQUIRE(host.setListenerPose(0, {2, 1.5f, 2}, 0.f, 0.2, 0.f));
  REQUIRE(host.tryListenerPose(0, third));
  const int64_t gap = third.publishedNs - second.publishedNs;
  CHECK(third.intervalNs == second.intervalNs + (gap - second.intervalNs) / 4);
}

TEST_CASE("poseWaitUntilNs: a stale pose waits for the host's next one when it comes in time",
          "[poses]") {
  constexpr int64_t ms = 1'000'000;
  ListenerPose p;
  p.publishedNs = 1000 * ms;
  p.intervalNs = 10 * ms;  // a host publishing every 10 ms
  const int64_t far = 2000 * ms;
  // 1 ms old: fresh (under a quarter of the interval), start now.
  CHECK(poseWaitUntilNs(p, 1001 * ms, far) == 1001 * ms);
  // 6 ms old: the next pose is due at 1010 ms; wait for it, until a quarter interval past due.
  CHECK(poseWaitUntilNs(p, 1006 * ms, far) == 1012 * ms + 500'000);
  // ... unless the frame must start before then to end within its period.
  CHECK(poseWaitUntilNs(p, 1006 * ms, 1011 * ms) == 1006 * ms);
  // A frame that cannot end within its period anyway (frames of 85 ms, longer than the
  // period) loses no deadline by waiting: it waits while that costs at most a quarter of it.
  CHECK(poseWaitUntilNs(p, 1006 * ms, 0, 85 * ms) == 1012 * ms + 500'000);
  // ... but not for a host slower than a quarter of its frames (a 6.5 ms wait for 20 ms).
  CHECK(poseWaitUntilNs(p, 1006 * ms, 0, 20 * ms) == 1006 * ms);
  // 15 ms old: the host is late (a stall); its pose may still come within two intervals.
  CHECK(poseWaitUntilNs(p, 1015 * ms, far) == 1020 * ms);
  CHECK(poseWaitUntilNs(p, 1015 * ms, 1018 * ms) == 1015 * ms);
  CHECK(poseWaitUntilNs(p, 1015 * ms, 0, 85 * ms) == 1020 * ms);
  // 21 ms old: the stream has stopped (past two intervals): start now.
  CHECK(poseWaitUntilNs(p, 1021 * ms, far) == 1021 * ms);
  // An overdue frame does not wait for a fresh pose's successor, nor for a stopped stream.
  CHECK(poseWaitUntilNs(p, 1001 * ms, 0, 85 * ms) == 1001 * ms);
  CHECK(poseWaitUntilNs(p, 1021 * ms, 0, 85 * ms) == 1021 * ms);
  // No stream (the first pose), or one too slow to align to (200 ms): start now.
  ListenerPose once = p;
  once.intervalNs = 0;
  CHECK(poseWaitUntilNs(once, 1006 * ms, far) == 1006 * ms);
  ListenerPose slow = p;
  slow.intervalNs = 200 * ms;
  CHECK(poseWaitUntilNs(slow, 1100 * ms, far) == 1100 * ms);
}
