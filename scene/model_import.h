// assimp's import of a level model (glTF, GLB, FBX) under dpc's input rules: a glTF level is
// checked whole before assimp reads it (scene/gltf_check.h: its container, URIs, limits and
// the glTF 2.0 rules assimp leaves unchecked); every file assimp opens is the level or a file
// inside the level's folder (a URI percent-decoded, symbolic links followed), a bounded regular
// file (never a FIFO or device, which would block or never end); and an import that assimp
// completes only by dropping data (faces with out-of-range indices) is refused instead of
// loading a different geometry without a word.
#pragma once

#include <assimp/Importer.hpp>
#include <nlohmann/json.hpp>
#include <string>

struct aiScene;

namespace dpc {

/// Imports modelFile (triangulated) into `importer`, which owns the result. Throws
/// InputError(modelFile, ...) naming the problem: what checkGltfLevel refuses in a glTF level,
/// a referenced file outside the level's folder or not a regular file of at most
/// kMaxMeshBytes, assimp's own error, faces assimp dropped, an incomplete scene. For a glTF
/// level, *gltfJson (if given) receives its parsed JSON. Any thread: imports are serialised
/// (assimp's logger, which reports the dropped data, is process-wide; a host's own logger is
/// kept and only lent to). Allocates.
const aiScene* importModel(Assimp::Importer& importer, const std::string& modelFile,
                           nlohmann::json* gltfJson = nullptr);

}  // namespace dpc
