// libFuzzer target: glTF 2.0 levels (scene/gltf_check.h, then assimp: scene/model_reader.h)
// through a fixed scene JSON naming the fuzzed level as the mesh, the door node as a moving
// object and the materials the seeds use. An input that starts with "glTF" is written as
// level.glb, any other as level.gltf; the folder also holds level.bin (1 KiB of zeros) for a
// .gltf's buffer URI to name. Every refusal must be an InputError; any other exception,
// crash, hang or sanitizer report is a finding. Corpus: fuzz/corpus/gltf
// (fuzz/make_gltf_seeds.py).
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "common/input_error.h"
#include "fuzz/fuzz_files.h"
#include "fuzz/fuzz_report.h"
#include "scene/scene.h"

namespace {

std::string scene(const char* level) {
  return std::string(R"({"mesh": ")") + level + R"(",
  "materials": {"walls": {"absorption": 0.1}, "floor": {"absorption": 0.3},
                "ceiling": {"absorption": 0.2}},
  "sources": [{"name": "s", "position": [2, 1.6, 3.5]}],
  "listener": {"position": [8.5, 1.6, 1.5], "radius": 0.5},
  "objects": [{"name": "door"}]})";
}

const std::string& put(const char* name, const std::string& text) {
  static std::vector<std::string> paths;
  paths.push_back(dpc::fuzz::put(name, reinterpret_cast<const uint8_t*>(text.data()), text.size()));
  return paths.back();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string glbScene = put("glb_scene.json", scene("level.glb"));
  static const std::string gltfScene = put("gltf_scene.json", scene("level.gltf"));
  static const bool bin = (put("level.bin", std::string(1024, '\0')), true);
  (void)bin;
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  dpc::fuzz::put(glb ? "level.glb" : "level.gltf", data, size);
  try {
    dpc::fuzz::acceptedScene(dpc::loadScene(glb ? glbScene : gltfScene));
  } catch (const dpc::InputError& e) {
    dpc::fuzz::refused(e.what());
  }
  return 0;
}
