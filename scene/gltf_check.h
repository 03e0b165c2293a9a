// A glTF 2.0 level checked against the rules of glTF 2.0 that keep assimp's read safe and
// faithful, and against dpc's limits, before assimp reads it (assimp 5.2 checks few of them:
// it recurses once per node level, allocates what an accessor or chunk claims, reads a
// sampler's keys past its output, and copies a BYTE position into a float as raw bytes).
// Private to scene/ (scene/model_import.cpp); docs/scene-format.md ("glTF and FBX levels")
// lists the rules for users.
//
// Checked, each refusal an InputError naming the level file and the JSON field
// ("meshes[0].primitives[1].mode", "animations[0].samplers[2].output"), the mesh's or
// animation's name in the message:
// - the container and the files its URIs name (scene/gltf_container.h);
// - asset.version 2.x; every extensionsRequired one that changes no geometry (materials,
//   textures);
// - buffers, bufferViews and accessors: every offset, length, stride and count within what
//   holds it; accessor component types and types of glTF 2.0; no sparse accessor, none
//   without a bufferView;
// - meshes: modes TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN (POINTS, LINES, LINE_LOOP and
//   LINE_STRIP refused by name), POSITION a VEC3 of FLOAT with bounds, every attribute of its
//   semantic's formats and count, indices of an unsigned integer type, index counts the mode
//   can use, no morph target, no Draco compression;
// - nodes: a forest (children in range, one parent each, no cycle) at most kMaxGltfNodeDepth
//   deep; matrix or translation/rotation/scale, finite, a rotation of non-zero length
//   (scene/quaternion.h); no skin; scenes list roots;
// - animations: channels on a node's translation, rotation or scale (not morph weights), each
//   node and path once per animation; samplers with a FLOAT SCALAR input with bounds, a FLOAT
//   output of the path's type and one value per key (three for CUBICSPLINE), interpolation
//   LINEAR, STEP or CUBICSPLINE;
// - the counts of kMaxGltfEntries, kMaxGltfNodes and kMaxGltfTriangles.
//
// Any thread that loads a scene; allocates (the parsed JSON); throws InputError.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

namespace dpc {

/// Deepest node in a level's node tree (a root is at depth 1): assimp and dpc walk the tree
/// recursively, about 1 kB of stack per level, so 128 levels stay far inside even a 256 kB
/// thread stack (a plugin host's worker); rigs and scene graphs nest a few dozen deep.
inline constexpr int kMaxGltfNodeDepth = 128;
/// Largest number of entries in any one top-level array (accessors, bufferViews, ...).
inline constexpr size_t kMaxGltfEntries = size_t(1) << 20;
/// Largest number of nodes, of primitives (all meshes together) and of animation channels
/// (all animations together): assimp makes a structure of over 1 kB for each.
inline constexpr size_t kMaxGltfNodes = size_t(1) << 16;
/// Largest number of triangles of all primitives together, counted from their index counts
/// (assimp keeps about 50 bytes per triangle).
inline constexpr uint64_t kMaxGltfTriangles = uint64_t(1) << 24;

/// Checks the level `file` (.gltf or .glb, a regular file of at most kMaxMeshBytes) and
/// returns its parsed JSON.
nlohmann::json checkGltfLevel(const std::string& file);

}  // namespace dpc
