// libFuzzer target: the OBJ reader (engine/scene), through a fixed valid scene JSON that names
// the fuzzed mesh and the materials the seeds use (those of the shipped shoebox, two_rooms and
// hall meshes). Every refusal must be an InputError; any other exception, crash, hang or
// sanitizer report is a finding. Corpus: fuzz/corpus/obj (the shipped meshes and an excerpt of
// the hall's, accepted: valid-*; the hall's vertices without its faces, refused).
#include <cstdint>

#include "common/input_error.h"
#include "fuzz/fuzz_files.h"
#include "fuzz/fuzz_report.h"
#include "scene/scene.h"

namespace {
const char kScene[] = R"({
  "mesh": "mesh.obj",
  "materials": {
    "walls": {"absorption": [0.1,0.1,0.1,0.1,0.1,0.1,0.1,0.1], "scattering": 0.2},
    "floor": {"absorption": [0.2,0.2,0.2,0.2,0.2,0.2,0.2,0.2], "scattering": 0.2},
    "ceiling": {"absorption": [0.3,0.3,0.3,0.3,0.3,0.3,0.3,0.3], "scattering": 0.1},
    "door": {"absorption": 0.1}, "partition": {"absorption": 0.1},
    "plaster": {"absorption": 0.05}, "concrete": {"absorption": 0.02},
    "glass": {"absorption": 0.04}, "wood_stage": {"absorption": 0.1},
    "wood_panel": {"absorption": 0.15}, "seats": {"absorption": 0.6},
    "curtain": {"absorption": 0.5}
  },
  "sources": [{"name": "s", "position": [2, 1.6, 3.5], "signal": "signals/speech.wav"}],
  "listener": {"position": [8.5, 1.6, 1.5], "radius": 0.5}
})";
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string scene = dpc::fuzz::put(
      "obj_scene.json", reinterpret_cast<const uint8_t*>(kScene), sizeof(kScene) - 1);
  dpc::fuzz::put("mesh.obj", data, size);
  try {
    dpc::fuzz::acceptedScene(dpc::loadScene(scene));
  } catch (const dpc::InputError& e) {
    dpc::fuzz::refused(e.what());
  }
  return 0;
}
