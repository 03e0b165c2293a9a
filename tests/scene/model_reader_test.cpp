// glTF levels (scene/model_reader.h): the two-room scene as a glTF level with an animated
// door (scenes/door_level.json, written by scenes/generate_door_level.py) loads the same
// triangles, materials and door keyframes as the OBJ + JSON scene it was made from
// (scenes/two_rooms.json), bit for bit.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/trigonometric.hpp>
#include <string>

#include "scene/scene.h"
#include "scene/trajectory.h"
#include "testing/temp_dir.h"

using namespace dpc;

namespace {

const std::string kScenes = std::string(DPC_SOURCE_DIR) + "/scenes";

template <class T>
bool sameBits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

/// Triangle t of the mesh as its three corners and its material's name.
struct Corner3 {
  glm::vec3 p[3];
};
Corner3 corners(const Mesh& m, size_t t) {
  return {{m.vertices[m.triangles[t][0]], m.vertices[m.triangles[t][1]],
           m.vertices[m.triangles[t][2]]}};
}

void requireSameTriangles(const SceneDesc& a, const Mesh& ma, const SceneDesc& b, const Mesh& mb) {
  REQUIRE(ma.triangles.size() == mb.triangles.size());
  for (size_t t = 0; t < ma.triangles.size(); ++t) {
    INFO("triangle " << t);
    const Corner3 ca = corners(ma, t), cb = corners(mb, t);
    for (int k = 0; k < 3; ++k) {
      INFO("corner " << k << ": " << ca.p[k].x << " " << ca.p[k].y << " " << ca.p[k].z << " vs "
                     << cb.p[k].x << " " << cb.p[k].y << " " << cb.p[k].z);
      CHECK(sameBits(ca.p[k], cb.p[k]));
    }
    CHECK(a.materials[ma.materialIndex[t]].name == b.materials[mb.materialIndex[t]].name);
  }
}

}  // namespace

TEST_CASE("The glTF door level loads as the OBJ + JSON scene it was made from", "[gltf]") {
  const SceneDesc obj = loadScene(kScenes + "/two_rooms.json");
  const SceneDesc gltf = loadScene(kScenes + "/door_level.json");
  requireSameTriangles(obj, obj.mesh, gltf, gltf.mesh);
  REQUIRE(gltf.objects.size() == 1);
  requireSameTriangles(obj, obj.objects[0].mesh, gltf, gltf.objects[0].mesh);
  const auto& ka = obj.objects[0].trajectory;
  const auto& kb = gltf.objects[0].trajectory;
  REQUIRE(ka.size() == kb.size());
  for (size_t k = 0; k < ka.size(); ++k) {
    INFO("keyframe " << k);
    CHECK(sameBits(ka[k].timeSeconds, kb[k].timeSeconds));
    CHECK(sameBits(ka[k].position, kb[k].position));
    CHECK(sameBits(ka[k].rotation, kb[k].rotation));
  }
  CHECK(gltf.objects[0].loop == obj.objects[0].loop);
}

namespace {

/// Runs python3 with scenes/gltffile.py importable; `body` writes files into `dir`.
void python(const std::string& body, const std::filesystem::path& dir) {
  const std::filesystem::path script = dir / "make.py";
  std::ofstream(script) << "import sys\nsys.path.insert(0, '" << kScenes
                        << "')\nfrom gltffile import Gltf\nimport os\nos.chdir('" << dir.string()
                        << "')\n"
                        << body;
  REQUIRE(std::system(("python3 " + script.string()).c_str()) == 0);
}

/// A level: a floor triangle (material "floor") and node "door" (material "walls") at
/// (5, 0, 3), whose translation steps from x = 5 to 6 at 1 s and to 7 at 2 s (STEP) while its
/// rotation turns linearly by 90 degrees about +y over 2 s (LINEAR).
constexpr const char* kSteppingDoor = R"(g = Gltf()
floor, walls = g.material('floor'), g.material('walls')
g.node('room', mesh=g.mesh('room', [(floor, [(0, 0, 0), (0, 0, 9), (9, 0, 0)], [(0, 1, 2)])]))
leaf = g.mesh('door', [(walls, [(0, 0, 0), (0, 2, 0), (0, 2, 1)], [(0, 1, 2)])])
door = g.node('door', mesh=leaf, translation=[5, 0, 3])
g.animation('move', [(door, 'translation', [0, 1, 2], [(5, 0, 3), (6, 0, 3), (7, 0, 3)], 'STEP'),
                     (door, 'rotation', [0, 2], [(0, 0, 0, 1), (0, 0.70710677, 0, 0.70710677)],
                      'LINEAR')])
g.save('level.glb')
)";

std::string levelScene(const std::string& objects) {
  return R"({ "mesh": "level.glb",
    "materials": { "floor": { "absorption": 0.1 }, "walls": { "absorption": 0.2 } },
    "sources": [ { "name": "s", "position": [1, 1, 1] } ],
    "listener": { "position": [2, 1, 1] }, "objects": )" +
         objects + "}";
}

}  // namespace

TEST_CASE("STEP keys hold until the next key and LINEAR rotation keys are slerped", "[gltf]") {
  test::TempDir dir("dpc_model_step");
  python(kSteppingDoor, dir.path());
  std::ofstream(dir.path() / "level.json") << levelScene(R"([ { "name": "door" } ])");
  const SceneDesc s = loadScene((dir.path() / "level.json").string());
  REQUIRE(s.objects.size() == 1);
  const ObjectDesc& door = s.objects[0];
  // Keys at 0, 1 - hold, 1, 2 - hold, 2 s (kStepHoldSeconds before each STEP key).
  REQUIRE(door.trajectory.size() == 5);
  const double hold = 1e-6;
  CHECK(door.trajectory[1].timeSeconds == 1.0 - hold);
  CHECK(door.trajectory[3].timeSeconds == 2.0 - hold);
  CHECK(objectPoseAt(door, 0.5).position.x == 5.f);
  CHECK(objectPoseAt(door, 0.999).position.x == 5.f);
  CHECK(objectPoseAt(door, 1.0).position.x == 6.f);
  CHECK(objectPoseAt(door, 1.5).position.x == 6.f);
  CHECK(objectPoseAt(door, 2.5).position.x == 7.f);
  // Rotation: half of 90 degrees at 1 s (slerp), to within float rounding of the keys.
  const glm::quat mid = objectPoseAt(door, 1.0).rotation;
  CHECK(mid.y == Approx(std::sin(glm::radians(22.5))).margin(1e-6));
  CHECK(mid.w == Approx(std::cos(glm::radians(22.5))).margin(1e-6));
}

TEST_CASE("Keyframes in the scene replace a node's animation", "[gltf]") {
  test::TempDir dir("dpc_model_override");
  python(kSteppingDoor, dir.path());
  std::ofstream(dir.path() / "level.json") << levelScene(
      R"([ { "name": "door", "trajectory": [ { "t": 0, "position": [1, 0, 1] } ] } ])");
  const SceneDesc s = loadScene((dir.path() / "level.json").string());
  REQUIRE(s.objects[0].trajectory.size() == 1);
  CHECK(objectPoseAt(s.objects[0], 1.5).position == glm::vec3(1, 0, 1));
  CHECK(s.objects[0].mesh.triangles.size() == 1);
}
