// The setup check (engine/setup_check.h) on what users load: every scene the project ships
// loads without a warning (a source standing on a wall, half its rays escaping, once warned in
// every render of the market), and a source put outside a room is warned about by name, so
// the first check cannot pass by the check saying nothing.
#include "engine/setup_check.h"

#include <catch2/catch.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("Setup check: no shipped scene warns", "[engine]") {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DPC_SOURCE_DIR) +
                                                                "/scenes")) {
    if (entry.path().extension() != ".json") continue;
    const SceneDesc scene = loadScene(entry.path().string());
    const std::vector<std::string> warnings = setupWarnings(scene);
    INFO(entry.path().string() << ": " << (warnings.empty() ? "" : warnings.front()));
    CHECK(warnings.empty());
    ++scenes;
  }
  CHECK(scenes >= 8);  // the shipped scenes were found
}

TEST_CASE("Setup check: a source outside the room is warned about by name", "[engine]") {
  SceneDesc scene =
      test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.2f, {3, 1.5f, 3.5f}, {7, 1.5f, 3.5f});
  REQUIRE(setupWarnings(scene).empty());
  SourceDesc outside = scene.sources.front();
  outside.name = "street";
  outside.position = {14.f, 1.5f, 3.5f};  // 4 m beyond the x = 10 m wall
  scene.sources.push_back(outside);
  const std::vector<std::string> warnings = setupWarnings(scene);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings.front().find("street") != std::string::npos);
}

TEST_CASE("Setup check: a listener whose centre lies in a sheet's plane is warned about",
          "[engine]") {
  // A ray that starts on a sheet does not hit it: looked for only from the centre, a partition
  // through the listener's centre went unseen (no warning, and the direct sound read 14.5 dB
  // above the free field at 63 Hz through a closed door's leaf).
  SceneDesc scene =
      test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.2f, {3, 1.5f, 3.5f}, {7, 1.5f, 3.5f});
  REQUIRE(setupWarnings(scene).empty());
  test::addPanel(scene.mesh, {7, 0, 0}, {0, 3, 0}, {0, 0, 7}, 0);  // the plane x = 7
  const std::vector<std::string> warnings = setupWarnings(scene);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings.front().find("reaches through a surface") != std::string::npos);
}

TEST_CASE("Setup check: a keyframe through a wall is warned about at its time", "[engine]") {
  // Start inside, then a keyframe typo 5 m beyond the x = 10 m wall at t = 2 s: the check at
  // time 0 alone said nothing, and the listener walked out of the room in silence.
  SceneDesc scene =
      test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.2f, {3, 1.5f, 3.5f}, {7, 1.5f, 3.5f});
  auto key = [](double t, glm::vec3 p) {
    Keyframe k;
    k.timeSeconds = t;
    k.position = p;
    return k;
  };
  ListenerDesc& l = scene.listeners.front();
  l.trajectory = {key(0.0, {7, 1.5f, 3.5f}), key(1.0, {8, 1.5f, 3.5f})};
  REQUIRE(setupWarnings(scene).empty());
  l.trajectory.push_back(key(2.0, {15, 1.5f, 3.5f}));
  const std::vector<std::string> warnings = setupWarnings(scene);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings.front().find("t = 2 s") != std::string::npos);
  CHECK(warnings.front().find("outside the room") != std::string::npos);
}

TEST_CASE("Setup check: a mesh whose units differ from the positions' is warned about",
          "[engine]") {
  // A level exported in the wrong unit: the room 0.1 x 0.03 x 0.07 (metres read as
  // centimetres), every point outside it, none enclosed, so no "outside the room" warning.
  SceneDesc scene =
      test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.2f, {3, 1.5f, 3.5f}, {7, 1.5f, 3.5f});
  for (glm::vec3& v : scene.mesh.vertices) v *= 0.01f;
  const std::vector<std::string> warnings = setupWarnings(scene);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings.front().find("outside its bounds") != std::string::npos);
}

TEST_CASE("Setup check: a source inside the listener's sphere is warned about", "[engine]") {
  // The direct sound's distance is clamped to R/2 there: a source 0.2 m from a 0.5 m sphere's
  // centre read G as at 0.25 m without a word.
  SceneDesc scene =
      test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.2f, {6.8f, 1.5f, 3.5f}, {7, 1.5f, 3.5f});
  const std::vector<std::string> warnings = setupWarnings(scene);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings.front().find("inside its 0.5 m sphere") != std::string::npos);
}

TEST_CASE("Setup check: an open scene over a ground plane is not called mis-scaled", "[engine]") {
  // The bounds warning must not fire where every point lies just outside a flat mesh's box
  // (a listener 1.6 m above a ground plane whose box is 0 m high).
  SceneDesc scene;
  scene.path = "<ground>";
  scene.materials.push_back(Material{"ground", Bands(0.1f), Bands(0.2f)});
  test::addPanel(scene.mesh, {-50, 0, -50}, {100, 0, 0}, {0, 0, 100}, 0);
  scene.sources.push_back(SourceDesc{});
  scene.sources.back().name = "talker";
  scene.sources.back().position = {0, 1.5f, 0};
  scene.listeners.push_back(ListenerDesc{});
  scene.listeners.back().name = "ear";
  scene.listeners.back().position = {5, 1.6f, 0};
  const std::vector<std::string> warnings = setupWarnings(scene);
  INFO((warnings.empty() ? "" : warnings.front()));
  CHECK(warnings.empty());
}
