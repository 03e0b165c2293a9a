// assimp's import of a level model (glTF, GLB, FBX) under dpc's input rules: every file it
// opens is a bounded regular file (never a FIFO or device, which would block or never end),
// a glTF's JSON is no deeper than kMaxJsonDepth (its parsers recurse once per level), and an
// import that assimp completes only by dropping data (faces with out-of-range indices) is
// refused instead of loading a different geometry without a word.
#pragma once

#include <assimp/Importer.hpp>
#include <string>

struct aiScene;

namespace dpc {

/// The JSON text of a .gltf, or the first (JSON) chunk of a .glb ("" for a .glb without one).
/// Control thread. Allocates; reads the whole file.
std::string gltfJsonText(const std::string& file);

/// Imports modelFile (triangulated) into `importer`, which owns the result. Throws
/// InputError(modelFile, ...) naming the problem: a referenced file that is not a regular
/// file of at most kMaxMeshBytes, JSON nested deeper than kMaxJsonDepth, assimp's own error,
/// faces assimp dropped, an incomplete scene. Any thread: imports are serialised (assimp's
/// logger, which reports the dropped data, is process-wide; a host's own logger is kept and
/// only lent to). Allocates.
const aiScene* importModel(Assimp::Importer& importer, const std::string& modelFile);

}  // namespace dpc
