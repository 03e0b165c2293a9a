// validate() (scene/validate.h): the rules between fields, on a SceneDesc as the C API builds
// one; and the one mesh builder (scene/mesh_builder.h): its cleaning rule.
#include "scene/validate.h"

#include <catch2/catch.hpp>
#include <string>

#include "common/input_error.h"
#include "scene/mesh_builder.h"
#include "scene/scene.h"

using namespace dpc;
using Catch::Matchers::Contains;

namespace {

const std::string kShoebox = std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json";

std::string error(const SceneDesc& scene) {
  try {
    validate(scene, Origin{"test", {}});
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

Keyframe key(double t) {
  Keyframe k;
  k.timeSeconds = t;
  k.position = {5, 1.6f, 3};
  return k;
}

}  // namespace

TEST_CASE("validate: rules between fields", "[validate]") {
  const SceneDesc good = loadScene(kShoebox);
  CHECK(error(good) == "");
  SceneDesc s = good;
  s.listeners.push_back(s.listeners.front());
  CHECK_THAT(error(s), Contains("test: listeners[1].name: duplicate listener name"));
  s = good;
  s.sources.front().name.clear();
  CHECK_THAT(error(s), Contains("test: sources[0].name: must not be empty"));
  s = good;
  s.sources.front().trajectory = {key(1.0), key(1.0)};
  CHECK_THAT(error(s), Contains("test: sources[0].trajectory[1].t: 1 is not greater than"));
  s = good;
  s.listeners.front().trajectory = {key(0.0), key(1.0)};
  s.listeners.front().trajectory[1].yawDegrees = 90.f;
  CHECK_THAT(error(s), Contains("test: listeners[0].trajectory[1].yaw: give \"yaw\" on every"));
  s = good;
  s.objects.push_back(ObjectDesc{});
  s.objects.back().name = "door";
  CHECK_THAT(error(s), Contains("test: objects[0].trajectory: at least one keyframe"));
  s = good;
  s.mesh.triangles.front()[2] = uint32_t(s.mesh.vertices.size());
  CHECK_THAT(error(s), Contains("test: mesh.triangles[0][2]: "));
  s = good;
  s.mesh.materialIndex.back() = uint32_t(s.materials.size());
  CHECK_THAT(error(s), Contains("test: mesh.materials[" +
                                std::to_string(s.mesh.triangles.size() - 1) + "]: "));
  s = good;
  s.materials.clear();
  CHECK_THAT(error(s), Contains("test: materials: at least one material is required"));
}

TEST_CASE("Mesh builder: zero-area and sliver triangles dropped with one warning", "[validate]") {
  RawMesh raw;
  raw.file = "data";
  raw.faceWord = "triangle";
  raw.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {1, 1e-7f, 0}};
  raw.triangles = {{0, 1, 2}, {0, 1, 3}, {0, 3, 4}};  // good, zero area, sliver
  raw.triangleFace = {0, 1, 2};
  std::vector<std::string> warnings;
  const Mesh mesh = buildMesh(raw, {0, 0, 0}, warnings);
  CHECK(mesh.triangles.size() == 1);
  REQUIRE(warnings.size() == 1);
  CHECK(warnings.front() ==
        "data: 2 degenerate (zero-area) triangle(s) dropped, the first from triangle 1");
  raw.triangles = {{0, 1, 3}};
  raw.triangleFace = {0};
  CHECK_THROWS_WITH(buildMesh(raw, {0}, warnings),
                    "data: all 1 triangles are degenerate (zero area); nothing to trace");
}
