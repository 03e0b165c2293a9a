// dpc-demo's live listener motion (apps/demo/keyboard_motion.h): the trajectory on scene time,
// keyboard moves along the heading, turns, pause, the next listener and quit.
#include "apps/demo/keyboard_motion.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "apps/demo/terminal.h"

using namespace dpc;
using dpc::demo::KeyboardMotion;

namespace {

/// Listener "a" standing at (1, 1, 1) facing +x; "b" walking +x from (2, 1, 1) at 1 m/s.
SceneDesc twoListeners() {
  SceneDesc scene;
  ListenerDesc a;
  a.name = "a";
  a.position = {1.f, 1.f, 1.f};
  ListenerDesc b;
  b.name = "b";
  b.trajectory = {Keyframe{0.0, {2.f, 1.f, 1.f}, {}, {}, {}, {}},
                  Keyframe{2.0, {4.f, 1.f, 1.f}, {}, {}, {}, {}}};
  scene.listeners = {a, b};
  return scene;
}

void requireNear(const glm::vec3& p, const glm::vec3& q) {
  REQUIRE(p.x == Approx(q.x).margin(1e-6));
  REQUIRE(p.y == Approx(q.y).margin(1e-6));
  REQUIRE(p.z == Approx(q.z).margin(1e-6));
}

}  // namespace

TEST_CASE("Keyboard motion: keys move along the heading and stop the trajectory", "[demo]") {
  const SceneDesc scene = twoListeners();
  KeyboardMotion m(scene, 0);
  requireNear(m.position(), {1.f, 1.f, 1.f});
  REQUIRE(m.key('w') == KeyboardMotion::Action::kNone);  // forward = +x at yaw 0
  requireNear(m.position(), {1.25f, 1.f, 1.f});
  REQUIRE(m.key(demo::kKeyRight) == KeyboardMotion::Action::kNone);  // right = +z at yaw 0
  requireNear(m.position(), {1.25f, 1.f, 1.25f});
  m.key('s');
  m.key('a');
  requireNear(m.position(), {1.f, 1.f, 1.f});
  m.advance(0.5);  // moved by the keyboard: scene time stands still
  REQUIRE(m.sceneTime() == 0.0);
  m.key('Q');
  m.advance(0.1);
  REQUIRE(m.yaw() == Approx(std::numbers::pi / 12));
  m.key('w');  // forward = (cos yaw, 0, -sin yaw)
  requireNear(m.position(), {1.f + 0.25f * float(std::cos(std::numbers::pi / 12)), 1.f,
                             1.f - 0.25f * float(std::sin(std::numbers::pi / 12))});
  m.key('e');
  m.advance(0.1);
  REQUIRE(m.yaw() == Approx(0.0).margin(1e-6));
}

TEST_CASE("Keyboard motion: space pauses, l plays the next listener on its trajectory, q quits",
          "[demo]") {
  const SceneDesc scene = twoListeners();
  KeyboardMotion m(scene, 0);
  m.advance(0.5);
  REQUIRE(m.sceneTime() == 0.5);
  m.key(' ');
  m.advance(1.0);
  REQUIRE(m.sceneTime() == 0.5);
  m.key(' ');
  REQUIRE(m.key('l') == KeyboardMotion::Action::kNextListener);
  REQUIRE(m.playedIndex() == 1);
  REQUIRE(m.played().name == "b");
  requireNear(m.position(), {2.5f, 1.f, 1.f});
  m.advance(1.0);
  requireNear(m.position(), {3.5f, 1.f, 1.f});
  REQUIRE(m.key('l') == KeyboardMotion::Action::kNextListener);
  REQUIRE(m.playedIndex() == 0);
  REQUIRE(m.key('x') == KeyboardMotion::Action::kNone);
  REQUIRE(m.key('q') == KeyboardMotion::Action::kQuit);
}
