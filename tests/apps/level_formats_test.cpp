// The same room as OBJ, glTF 2.0 (.glb) and FBX gives the same energy response for a seed: the
// shoebox's OBJ is converted by assimp's own exporters (independent of dpc's reader and of
// scenes/gltffile.py), each scene rendered offline, and the last frame's energy responses
// compared bin by bin. The shoebox's coordinates are whole metres, exact in every format's
// float32, so the equality is exact rather than within rounding. The FBX's UnitScaleFactor
// (centimetres per unit) is honoured: set to 1, the room reads 100 times smaller.
#include <assimp/scene.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "scene/scene.h"
#include "short_render.h"
#include "testing/temp_dir.h"

using namespace dpc;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

const std::string kScenes = std::string(DPC_SOURCE_DIR) + "/scenes";

/// scenes/shoebox.obj written by assimp's exporter `format` ("glb2", "fbxa") to `out`.
void convertShoebox(const std::string& format, const fs::path& out) {
  Assimp::Importer importer;
  const aiScene* s = importer.ReadFile(kScenes + "/shoebox.obj", 0);
  REQUIRE(s);
  Assimp::Exporter exporter;
  REQUIRE(exporter.Export(s, format, out.string()) == AI_SUCCESS);
}

/// Replaces the FBX's UnitScaleFactor (assimp's exporter writes 1: centimetres) by `value`.
void setFbxUnit(const fs::path& fbx, const std::string& value) {
  std::ifstream in(fbx);
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::string key = "\"UnitScaleFactor\", \"double\", \"Number\", \"\", ";
  const size_t at = s.find(key);
  REQUIRE(at != std::string::npos);
  const size_t end = s.find('\n', at);
  s.replace(at + key.size(), end - at - key.size(), value);
  std::ofstream(fbx) << s;
}

/// scenes/shoebox.json with its mesh (and signal) pointing at absolute paths, saved in `dir`.
std::string shoeboxWithMesh(const fs::path& dir, const std::string& mesh) {
  std::ifstream in(kScenes + "/shoebox.json");
  json scene = json::parse(in);
  scene["mesh"] = mesh;
  for (json& s : scene["sources"]) s["signal"] = kScenes + "/" + s["signal"].get<std::string>();
  const fs::path path = dir / (fs::path(mesh).filename().string() + ".json");
  std::ofstream(path) << scene.dump(1);
  return path.string();
}

EnergyResponse lastEnergy(const SceneDesc& scene) {
  return test::shortRender(scene, 400, 0.3).lastEnergy.at(0);
}

}  // namespace

TEST_CASE("The shoebox as OBJ, glTF and FBX gives the same energy response", "[gltf][fbx]") {
  test::TempDir dir("dpc_level_formats");
  convertShoebox("glb2", dir.path() / "shoebox.glb");
  convertShoebox("fbxa", dir.path() / "shoebox.fbx");
  setFbxUnit(dir.path() / "shoebox.fbx", "100");  // one unit = 100 cm: metres
  const SceneDesc obj = loadScene(kScenes + "/shoebox.json");
  const EnergyResponse reference = lastEnergy(obj);
  double total = 0;
  for (const Bands& b : reference.bins()) total += b[3];
  REQUIRE(total > 0);  // a response to compare: the 500 Hz band heard something
  for (const char* mesh : {"shoebox.glb", "shoebox.fbx"}) {
    INFO(mesh);
    const SceneDesc level = loadScene(shoeboxWithMesh(dir.path(), (dir.path() / mesh).string()));
    REQUIRE(level.mesh.triangles.size() == obj.mesh.triangles.size());
    const EnergyResponse e = lastEnergy(level);
    REQUIRE(e.binCount() == reference.binCount());
    bool same = true;
    for (size_t k = 0; k < e.binCount(); ++k)
      for (int b = 0; b < kNumBands; ++b) same = same && e.bins()[k][b] == reference.bins()[k][b];
    CHECK(same);
  }
}

TEST_CASE("An FBX in centimetres is read in metres", "[fbx]") {
  test::TempDir dir("dpc_level_units");
  convertShoebox("fbxa", dir.path() / "shoebox.fbx");  // UnitScaleFactor 1: centimetres
  const SceneDesc cm =
      loadScene(shoeboxWithMesh(dir.path(), (dir.path() / "shoebox.fbx").string()));
  float largest = 0;
  for (const glm::vec3& v : cm.mesh.vertices) largest = std::max({largest, v.x, v.y, v.z});
  CHECK(largest == Approx(0.10f).epsilon(1e-6));  // the 10 m room's 10 units as centimetres
}
