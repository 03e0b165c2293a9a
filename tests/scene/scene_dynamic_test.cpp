// Scene dynamics: trajectories of listeners, sources and objects, several listeners, and the
// errors of dynamic-scene input.
#include <catch2/catch.hpp>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <string>

#include "common/input_error.h"
#include "scene/enum_names.h"
#include "scene/orientation.h"
#include "scene/scene.h"
#include "scene/trajectory.h"
#include "tests/scene/scene_fixture.h"

using namespace dpc;
using namespace dpc::test;
using Catch::Matchers::Contains;

TEST_CASE("listenerPositionAt interpolates, clamps and loops", "[scene][trajectory]") {
  ListenerDesc l;
  l.position = {9.f, 9.f, 9.f};
  CHECK(listenerPositionAt(l, 3.0) == glm::vec3(9.f, 9.f, 9.f));  // static

  l.trajectory = {key(0.0, {0.f, 0.f, 0.f}), key(2.0, {2.f, 0.f, 0.f}), key(4.0, {2.f, 4.f, 0.f})};
  auto near = [](glm::vec3 a, glm::vec3 b) {
    return std::abs(a.x - b.x) < 1e-5f && std::abs(a.y - b.y) < 1e-5f &&
           std::abs(a.z - b.z) < 1e-5f;
  };
  CHECK(near(listenerPositionAt(l, 1.0), {1.f, 0.f, 0.f}));
  CHECK(near(listenerPositionAt(l, 2.0), {2.f, 0.f, 0.f}));
  CHECK(near(listenerPositionAt(l, 3.0), {2.f, 2.f, 0.f}));
  CHECK(near(listenerPositionAt(l, 3.5), {2.f, 3.f, 0.f}));
  CHECK(near(listenerPositionAt(l, -1.0), {0.f, 0.f, 0.f}));  // clamped before
  CHECK(near(listenerPositionAt(l, 4.0), {2.f, 4.f, 0.f}));
  CHECK(near(listenerPositionAt(l, 7.0), {2.f, 4.f, 0.f}));  // clamped after

  l.loop = true;  // period 4 s
  CHECK(near(listenerPositionAt(l, 5.0), {1.f, 0.f, 0.f}));
  CHECK(near(listenerPositionAt(l, 4.0), {0.f, 0.f, 0.f}));
  CHECK(near(listenerPositionAt(l, 11.0), {2.f, 2.f, 0.f}));
  CHECK(near(listenerPositionAt(l, -1.0), {2.f, 2.f, 0.f}));  // wraps to t = 3

  // A trajectory starting later loops over [t_first, t_last).
  l.trajectory = {key(1.0, {0.f, 0.f, 0.f}), key(3.0, {0.f, 0.f, 2.f})};
  CHECK(near(listenerPositionAt(l, 0.5), {0.f, 0.f, 1.5f}));
  CHECK(near(listenerPositionAt(l, 3.5), {0.f, 0.f, 0.5f}));
  l.loop = false;
  CHECK(near(listenerPositionAt(l, 0.5), {0.f, 0.f, 0.f}));

  l.trajectory = {key(2.0, {1.f, 2.f, 3.f})};  // a single keyframe is static
  CHECK(listenerPositionAt(l, 0.0) == glm::vec3(1.f, 2.f, 3.f));
  CHECK(listenerPositionAt(l, 10.0) == glm::vec3(1.f, 2.f, 3.f));
}

TEST_CASE("A trajectory alone sets the listener's start position", "[scene][trajectory]") {
  Fixture f;
  f.scene["listener"].erase("position");
  f.scene["listener"]["trajectory"] = json::parse(
      R"([{"t": 0, "position": [0.2, 0.5, 0.5]}, {"t": 1.5, "position": [0.8, 0.5, 0.5]}])");
  f.scene["listener"]["loop"] = true;
  const SceneDesc s = f.load();
  CHECK(s.listeners[0].position == glm::vec3(0.2f, 0.5f, 0.5f));
  CHECK(s.listeners[0].trajectory.size() == 2);
  CHECK(s.listeners[0].loop);
}

TEST_CASE("parseEstimator and parseDpcWeighting", "[scene]") {
  CHECK(parseEstimator("dpc") == Estimator::kDpc);
  CHECK(parseEstimator("path_tracing") == Estimator::kPathTracing);
  CHECK_FALSE(parseEstimator("DPC").has_value());
  CHECK(parseDpcWeighting("ema") == DpcWeighting::kEma);
  CHECK(parseDpcWeighting("seed") == DpcWeighting::kSeed);
  CHECK(parseDpcWeighting("window") == DpcWeighting::kWindow);
  CHECK_FALSE(parseDpcWeighting("").has_value());
}

// ---------------------------------------------------------------------------------------------
// Dynamic scenes: source trajectories, moving objects, several listeners.

TEST_CASE("Source trajectory interpolates, clamps and loops, position defaults to the first key",
          "[scene][dynamic]") {
  Fixture fx;
  fx.scene["sources"][0].erase("position");
  fx.scene["sources"][0]["trajectory"] =
      json::parse(R"([ { "t": 1, "position": [0, 0, 0] }, { "t": 3, "position": [2, 0, 0] } ])");
  SceneDesc s = fx.load();
  const SourceDesc& src = s.sources[0];
  CHECK(src.position == glm::vec3(0.f));
  CHECK(sourcePositionAt(src, 0.0) == glm::vec3(0.f));         // clamped before the first key
  CHECK(sourcePositionAt(src, 2.0) == glm::vec3(1.f, 0, 0));   // halfway
  CHECK(sourcePositionAt(src, 10.0) == glm::vec3(2.f, 0, 0));  // clamped after the last
  fx.scene["sources"][0]["trajectory_loop"] = true;
  s = fx.load();
  CHECK(sourcePositionAt(s.sources[0], 4.0).x == Approx(1.0));  // 4 -> 2 (period 2 s)
  CHECK_FALSE(s.sources[0].loop);  // the dry signal's loop is a different key
}

TEST_CASE("Object poses: linear position, slerped rotation along the shorter arc",
          "[scene][dynamic]") {
  Fixture fx;
  fx.write("door.obj", Fixture::kCube);
  // 90 degrees about +y at t = 2: [x, y, z, w] = [0, sin 45, 0, cos 45]. The second key
  // is given with the opposite sign (same rotation) to check the shorter-arc choice.
  fx.scene["objects"] = json::parse(R"([ { "name": "door", "mesh": "door.obj", "trajectory": [
      { "t": 0, "position": [0, 0, 0] },
      { "t": 2, "position": [4, 0, 0], "rotation": [0, -0.70710678, 0, -0.70710678] } ] } ])");
  const SceneDesc s = fx.load();
  REQUIRE(s.objects.size() == 1);
  CHECK(s.objects[0].mesh.triangles.size() == 12);
  const Pose p = objectPoseAt(s.objects[0], 1.0);
  CHECK(p.position.x == Approx(2.0));
  // Halfway: 45 degrees about +y maps +x to (cos 45, 0, -sin 45).
  const glm::vec3 x = p.rotation * glm::vec3(1, 0, 0);
  CHECK(x.x == Approx(std::sqrt(0.5)).margin(1e-5));
  CHECK(x.z == Approx(-std::sqrt(0.5)).margin(1e-5));
  WorldState world;
  evaluateWorld(s, 2.0, world);
  CHECK(world.objectPoses.size() == 1);
  CHECK(world.sourcePositions.size() == 1);
  CHECK(world.listenerPositions.size() == 1);
}

TEST_CASE("Several listeners: names, selection, unknown name", "[scene][dynamic]") {
  Fixture fx;
  fx.scene.erase("listener");
  fx.scene["listeners"] = json::parse(R"([ { "name": "a", "position": [0.2, 0.5, 0.5] },
                                           { "name": "b", "position": [0.8, 0.5, 0.5] } ])");
  SceneDesc s = fx.load();
  REQUIRE(s.listeners.size() == 2);
  CHECK(s.listeners[0].name == "a");
  CHECK(listenerIndex(s, "b", "--listener") == 1);
  CHECK(s.listeners[1].position.x == Approx(0.8));
  try {
    listenerIndex(s, "c", "--listener");
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Contains("--listener") && Contains("\"c\"") && Contains("\"b\""));
  }
}

TEST_CASE("Listener roll: up turns about forward, angles round-trip, keyframes interpolate it",
          "[scene][trajectory]") {
  constexpr float kDeg = 3.14159265f / 180.f;
  auto near = [](glm::vec3 a, glm::vec3 b) { return glm::length(a - b) < 1e-5f; };
  // Roll +90 at rest: forward stays +x, up turns to the right side, +z (x cross y).
  const Orientation tilted{0.f, 0.f, 90.f * kDeg};
  CHECK(near(tilted.forward(), {1.f, 0.f, 0.f}));
  CHECK(near(tilted.up(), {0.f, 0.f, 1.f}));
  // Any yaw, pitch (inside the poles) and roll: orthonormal axes that give the angles back.
  for (float yaw : {-170.f, -30.f, 0.f, 75.f}) {
    for (float pitch : {-80.f, -10.f, 0.f, 45.f}) {
      for (float roll : {-179.f, -60.f, 0.f, 20.f, 135.f}) {
        const Orientation o{yaw * kDeg, pitch * kDeg, roll * kDeg};
        const glm::vec3 f = o.forward(), u = o.up();
        CHECK(std::abs(glm::dot(f, u)) < 1e-5f);
        CHECK(glm::length(u) == Approx(1.f).margin(1e-5f));
        const Orientation back = orientationFromAxes(f, u);
        CHECK(back.yawRadians == Approx(o.yawRadians).margin(1e-4f));
        CHECK(back.pitchRadians == Approx(o.pitchRadians).margin(1e-4f));
        CHECK(back.rollRadians == Approx(o.rollRadians).margin(1e-4f));
      }
    }
  }
  // Keyframes: roll interpolates linearly like pitch; the listener's own roll without them.
  ListenerDesc l;
  l.rollDegrees = 10.f;
  CHECK(listenerOrientationAt(l, 1.0).rollRadians == Approx(10.f * kDeg));
  Keyframe a = key(0.0, {0.f, 0.f, 0.f}), b = key(2.0, {0.f, 0.f, 0.f});
  a.yawDegrees = 0.f;
  b.yawDegrees = 0.f;
  a.rollDegrees = -30.f;
  b.rollDegrees = 30.f;
  l.trajectory = {a, b};
  CHECK(listenerOrientationAt(l, 0.5).rollRadians == Approx(-15.f * kDeg));
  CHECK(listenerOrientationAt(l, 3.0).rollRadians == Approx(30.f * kDeg));
}

TEST_CASE("Dynamic-scene bad input names the file and the field", "[scene][dynamic][errors]") {
  const std::string door = R"([ { "name": "door", "mesh": "door.obj", "trajectory": [
      { "t": 0, "position": [0, 0, 0] } ] } ])";
  SECTION("zero-length quaternion") {
    Fixture fx;
    fx.write("door.obj", Fixture::kCube);
    fx.scene["objects"] = json::parse(door);
    fx.scene["objects"][0]["trajectory"][0]["rotation"] = json::parse("[0, 0, 0, 0]");
    CHECK_THAT(fx.error(), Contains("scene.json: objects[0].trajectory[0].rotation:") &&
                               Contains("zero length"));
  }
  SECTION("object keyframe times not increasing") {
    Fixture fx;
    fx.write("door.obj", Fixture::kCube);
    fx.scene["objects"] = json::parse(door);
    fx.scene["objects"][0]["trajectory"].push_back(json::parse(R"({"t": 0, "position": [1,0,0]})"));
    CHECK_THAT(fx.error(),
               Contains("objects[0].trajectory[1].t:") && Contains("strictly increasing"));
  }
  SECTION("source keyframe times not increasing") {
    Fixture fx;
    fx.scene["sources"][0]["trajectory"] =
        json::parse(R"([ { "t": 2, "position": [0, 0, 0] }, { "t": 1, "position": [1, 0, 0] } ])");
    CHECK_THAT(fx.error(), Contains("sources[0].trajectory[1].t:"));
  }
  SECTION("object mesh missing") {
    Fixture fx;
    fx.scene["objects"] = json::parse(door);
    CHECK_THAT(fx.error(), Contains("scene.json: objects[0].mesh:") && Contains("not found"));
  }
  SECTION("object mesh degenerate") {
    Fixture fx;
    fx.write("door.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nusemtl walls\nf 1 2 3\n");
    fx.scene["objects"] = json::parse(door);
    CHECK_THAT(fx.error(), Contains("door.obj") && Contains("degenerate"));
  }
  SECTION("undefined material in an object mesh") {
    Fixture fx;
    fx.write("door.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl oak\nf 1 2 3\n");
    fx.scene["objects"] = json::parse(door);
    CHECK_THAT(fx.error(), Contains("door.obj: usemtl oak:") && Contains("not defined"));
  }
  SECTION("duplicate object names") {
    Fixture fx;
    fx.write("door.obj", Fixture::kCube);
    fx.scene["objects"] = json::parse(door);
    fx.scene["objects"].push_back(fx.scene["objects"][0]);
    CHECK_THAT(fx.error(), Contains("objects[1].name:") && Contains("duplicate"));
  }
  SECTION("listener roll out of range") {
    Fixture fx;
    fx.scene["listener"]["roll"] = 190;
    CHECK_THAT(fx.error(), Contains("scene.json: listener.roll:") && Contains("[-180, 180]"));
  }
  SECTION("keyframe roll not a number") {
    Fixture fx;
    fx.scene["listener"]["trajectory"] =
        json::parse(R"([ { "t": 0, "position": [0.5, 0.5, 0.5], "yaw": 0, "roll": "up" } ])");
    CHECK_THAT(fx.error(), Contains("listener.trajectory[0].roll:"));
  }
  SECTION("duplicate listener names") {
    Fixture fx;
    fx.scene.erase("listener");
    fx.scene["listeners"] = json::parse(R"([ { "name": "a", "position": [0.2, 0.5, 0.5] },
                                             { "name": "a", "position": [0.8, 0.5, 0.5] } ])");
    CHECK_THAT(fx.error(), Contains("listeners[1].name:") && Contains("duplicate"));
  }
  SECTION("listener and listeners together") {
    Fixture fx;
    fx.scene["listeners"] = json::parse(R"([ { "name": "a", "position": [0.2, 0.5, 0.5] } ])");
    CHECK_THAT(fx.error(), Contains("scene.json: listeners:"));
  }
}
