// glTF levels (scene/model_reader.h): the two-room scene as a glTF level with an animated
// door (scenes/door_level.json, written by scenes/generate_door_level.py) loads the same
// triangles, materials and door keyframes as the OBJ + JSON scene it was made from
// (scenes/two_rooms.json), bit for bit.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <string>
#include <vector>

#include "scene/scene.h"
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

namespace {

/// An ASCII FBX 7.4 level: a floor quad of 1000 x 700 file units (material "floor"), y up,
/// with the given UnitScaleFactor (centimetres per file unit).
std::string fbxFloor(const char* cmPerUnit) {
  return std::string(R"(; FBX 7.4.0 project file
FBXHeaderExtension:  {
	FBXHeaderVersion: 1003
	FBXVersion: 7400
}
GlobalSettings:  {
	Version: 1000
	Properties70:  {
		P: "UpAxis", "int", "Integer", "",1
		P: "UpAxisSign", "int", "Integer", "",1
		P: "FrontAxis", "int", "Integer", "",2
		P: "FrontAxisSign", "int", "Integer", "",1
		P: "CoordAxis", "int", "Integer", "",0
		P: "CoordAxisSign", "int", "Integer", "",1
		P: "UnitScaleFactor", "double", "Number", "",)") +
         cmPerUnit + R"(
	}
}
Objects:  {
	Geometry: 1000, "Geometry::floor", "Mesh" {
		Vertices: *12 {
			a: 0,0,0,0,0,700,1000,0,700,1000,0,0
		}
		PolygonVertexIndex: *4 {
			a: 0,1,2,-4
		}
		LayerElementMaterial: 0 {
			Version: 101
			MappingInformationType: "AllSame"
			ReferenceInformationType: "IndexToDirect"
			Materials: *1 {
				a: 0
			}
		}
		Layer: 0 {
			Version: 100
			LayerElement:  {
				Type: "LayerElementMaterial"
				TypedIndex: 0
			}
		}
	}
	Model: 2000, "Model::floor", "Mesh" {
		Version: 232
	}
	Material: 3000, "Material::floor", "" {
		Version: 102
	}
}
Connections:  {
	C: "OO",1000,2000
	C: "OO",2000,0
	C: "OO",3000,2000
}
)";
}

/// The largest x of the scene's vertices after loading the FBX floor with `cmPerUnit`.
float fbxFloorWidth(const char* cmPerUnit) {
  test::TempDir dir("dpc_model_fbx");
  std::ofstream(dir.path() / "level.fbx") << fbxFloor(cmPerUnit);
  std::ofstream(dir.path() / "level.json") << R"({ "mesh": "level.fbx",
    "materials": { "floor": { "absorption": 0.1 } },
    "sources": [ { "name": "s", "position": [1, 1, 1] } ], "listener": { "position": [2, 1, 1] } })";
  const SceneDesc s = loadScene((dir.path() / "level.json").string());
  float x = 0.f;
  for (const glm::vec3& v : s.mesh.vertices) x = std::max(x, v.x);
  return x;
}

}  // namespace

TEST_CASE("An FBX level's UnitScaleFactor turns its units into metres, and one <= 0 is refused",
          "[gltf]") {
  // 1000 units of 1 cm are 10 m; of 100 cm (Blender's metres), 1000 m.
  CHECK(fbxFloorWidth("1") == 10.f);
  CHECK(fbxFloorWidth("100") == 1000.f);
  // Zero would collapse the level (assimp refuses it itself), a negative scale mirror it.
  CHECK_THROWS_WITH(fbxFloorWidth("-100"),
                    Catch::Contains("level.fbx: UnitScaleFactor: -100 is not a unit length"));
  CHECK_THROWS_WITH(fbxFloorWidth("0"), Catch::Contains("UnitScaleFactor must be non-zero"));
}

namespace {

/// The shoebox of scenes/shoebox.obj as two levels: plain.glb, and mirrored.glb whose room node
/// mirrors it in x about x = 5 (scale -1, translation 10): the same box, its faces wound the
/// other way round in the file.
constexpr const char* kMirroredRoom = R"(from gltffile import read_obj
for name, trs in [('plain', {}), ('mirrored', {'scale': [-1, 1, 1], 'translation': [10, 0, 0]})]:
    g = Gltf()
    runs = read_obj(')" DPC_SOURCE_DIR R"(/scenes/shoebox.obj')
    g.node('room', mesh=g.mesh('room', [(g.material(m), p, t) for m, p, t in runs]), **trs)
    g.save(name + '.glb')
)";

/// How many triangles of `m` face the point `inside`: their normal (by their winding) points
/// from the triangle towards it.
size_t trianglesFacing(const Mesh& m, const glm::vec3& inside) {
  size_t facing = 0;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const Corner3 c = corners(m, t);
    const glm::vec3 n = glm::cross(c.p[1] - c.p[0], c.p[2] - c.p[0]);
    facing += glm::dot(n, inside - (c.p[0] + c.p[1] + c.p[2]) / 3.f) > 0.f;
  }
  return facing;
}

}  // namespace

TEST_CASE("A mirroring node keeps its triangles' front side (glTF reverses their winding)",
          "[gltf]") {
  test::TempDir dir("dpc_model_mirror");
  python(kMirroredRoom, dir.path());
  size_t facing[2] = {};
  for (int k = 0; k < 2; ++k) {
    std::ofstream(dir.path() / "level.json")
        << R"({ "mesh": ")" << (k ? "mirrored" : "plain") << R"(.glb",
      "materials": { "walls": { "absorption": 0.1 }, "floor": { "absorption": 0.2 },
        "ceiling": { "absorption": 0.3 } }, "sources": [ { "name": "s", "position": [2, 1, 1] } ],
      "listener": { "position": [8, 1, 1] } })";
    const Mesh mesh = loadScene((dir.path() / "level.json").string()).mesh;
    REQUIRE(mesh.triangles.size() == 12);
    facing[k] = trianglesFacing(mesh, glm::vec3(5.f, 1.5f, 3.5f));
  }
  // shoebox.obj winds all its faces one way (all 12 face the centre, or none does); the mirrored
  // level's faces keep the same side as the plain one's.
  CHECK((facing[0] == 0 || facing[0] == 12));
  CHECK(facing[1] == facing[0]);
}
