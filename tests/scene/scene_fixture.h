// The scene tests' fixture: a temporary folder with a minimal valid scene (scene.json,
// cube.obj, dry.wav) whose JSON a test edits before loading it, and a keyframe helper.
#pragma once

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "common/input_error.h"
#include "scene/scene.h"
#include "testing/temp_dir.h"

namespace dpc::test {

namespace fs = std::filesystem;
using nlohmann::json;

inline const std::string kSourceDir = DPC_SOURCE_DIR;

inline Keyframe key(double t, glm::vec3 p) {
  Keyframe k;
  k.timeSeconds = t;
  k.position = p;
  return k;
}

/// A fresh temporary folder holding a valid minimal scene: scene.json, cube.obj (unit cube,
/// 12 triangles, materials "walls" and "floor") and dry.wav (existence is all that is checked).
class Fixture {
 public:
  Fixture() : dir_("dpc_scene_test") {
    write("dry.wav", "RIFF");
    write("cube.obj", kCube);
    scene = json::parse(R"({
      "mesh": "cube.obj",
      "materials": {
        "walls": { "absorption": [0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1], "scattering": 0.2,
                   "source": "made up for the test" },
        "floor": { "absorption": 0.3 }
      },
      "sources": [ { "name": "talker", "position": [0.5, 0.5, 0.5], "signal": "dry.wav" } ],
      "listener": { "position": [0.2, 0.5, 0.5], "radius": 0.1 }
    })");
  }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_.path() / name) << text;
  }
  std::string path(const std::string& name) const { return (dir_.path() / name).string(); }

  SceneDesc load() const {
    write("scene.json", scene.dump(2));
    return loadScene(path("scene.json"));
  }

  /// Loads and returns the InputError's message; fails the test if nothing is thrown.
  std::string error() const {
    try {
      load();
    } catch (const InputError& e) {
      return e.what();
    }
    FAIL("expected an InputError");
    return "";
  }

  static constexpr const char* kCube = R"(# unit cube
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
v 0 0 1
v 1 0 1
v 0 1 1
v 1 1 1
usemtl floor
f 1 2 6
f 1 6 5
usemtl walls
f 3 7 8
f 3 8 4
f 1 5 7
f 1 7 3
f 2 4 8
f 2 8 6
f 1 3 4
f 1 4 2
f 5 6 8
f 5 8 7
)";

  json scene;

 private:
  TempDir dir_;
};

}  // namespace dpc::test
