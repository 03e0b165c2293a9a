// glTF levels (scene/model_reader.h): the two-room scene as a glTF level with an animated
// door (scenes/door_level.json, written by scenes/generate_door_level.py) loads the same
// triangles, materials and door keyframes as the OBJ + JSON scene it was made from
// (scenes/two_rooms.json), bit for bit.
#include <catch2/catch.hpp>
#include <cstring>
#include <string>

#include "scene/scene.h"

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
