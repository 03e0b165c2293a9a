// The scene model's whole-scene functions: a listener looked up by name, and the files a run
// reads. The readers are scene/scene_json.cpp and scene/obj_reader.cpp; the checks
// scene/validate.cpp; the helpers scene/trajectory.cpp, scene/orientation.cpp,
// scene/enum_names.cpp and scene/mesh_topology.cpp.
#include "scene/scene.h"

#include "common/input_error.h"
#include "scene/gltf_container.h"

namespace dpc {

size_t listenerIndex(const SceneDesc& scene, const std::string& name, const std::string& flag) {
  std::string known;
  for (size_t i = 0; i < scene.listeners.size(); ++i) {
    if (scene.listeners[i].name == name) return i;
    known += (known.empty() ? "\"" : ", \"") + scene.listeners[i].name + "\"";
  }
  throw InputError(
      "command line", flag,
      "no listener named \"" + name + "\"" + " in " + scene.path + " (listeners: " + known + ")");
}

namespace {

/// A mesh file and, for a glTF level, the buffer and image files it names.
void addMesh(const std::string& path, const std::string& what,
             std::vector<std::pair<std::string, std::string>>& inputs) {
  inputs.push_back({path, what});
  if (!isGltfFile(path)) return;
  for (const auto& file : gltfReferencedFiles(path))
    inputs.push_back({file.string(), "a file of " + what + " (" + path + ")"});
}

}  // namespace

std::vector<std::pair<std::string, std::string>> sceneInputFiles(const SceneDesc& scene,
                                                                 const std::string& scenePath) {
  std::vector<std::pair<std::string, std::string>> inputs = {{scenePath, "the scene file"}};
  addMesh(scene.meshPath, "the mesh", inputs);
  for (const auto& obj : scene.objects) addMesh(obj.meshPath, "an object's mesh", inputs);
  for (const auto& src : scene.sources) inputs.push_back({src.signalPath, "a dry signal"});
  if (!scene.audio.hrtfPath.empty()) inputs.push_back({scene.audio.hrtfPath, "the SOFA file"});
  // layout:FILE.json is read; a preset's name ("7.1") is not, and matches an output only if a
  // file of that name exists there.
  if (scene.audio.output == OutputFormat::kLoudspeakers && !scene.audio.layoutName.empty())
    inputs.push_back({scene.audio.layoutName, "the loudspeaker layout"});
  return inputs;
}

}  // namespace dpc
