// glTF 2.0 (.gltf, .glb) and FBX (.fbx) levels, read with Debian's assimp 5.2: the static
// triangles in world coordinates, and the nodes a scene names in `objects` as moving objects
// with their own triangles and their animation as a trajectory. docs/scene-format.md
// ("glTF and FBX levels") is the user's view; why assimp and not tinygltf is there too.
//
// Frames and units: a node's world transform is the product of its ancestors' (glTF: y up,
// metres, as dpc; FBX: the file's UnitScaleFactor, centimetres per unit (> 0), turns units into
// metres, and an up axis other than y is refused). Material names select the scene's
// materials as OBJ usemtl names do (a primitive without a material uses "default").
//
// Control thread; allocates; throws InputError naming the model file and what in it is wrong
// (a mesh, vertex, material, node or animation), or the scene file and its field.
#pragma once

#include <string>
#include <vector>

#include "scene/obj_reader.h"
#include "scene/scene.h"

namespace dpc {

/// True when `path` ends in .gltf, .glb or .fbx (any case).
bool isModelFile(const std::string& path);

/// A node the scene asks for: its name and the scene field that asks (for errors).
struct ModelObjectRequest {
  std::string name;   ///< the node's name in the file, which is the object's name
  std::string field;  ///< "objects[1].name"
};

/// A requested node: the triangles of its subtree in the node's own frame (metres, the node's
/// and its ancestors' scale applied; world = rotation * local + position) and its trajectory:
/// its animation's keys (docs/scene-format.md says how LINEAR and STEP become keyframes) or,
/// without animation, one keyframe at t = 0 holding the node's pose.
struct ModelObject {
  std::string name;
  RawMesh mesh;
  std::vector<ObjectKeyframe> trajectory;
};

struct RawModel {
  RawMesh world;                     ///< triangles outside the requested subtrees, world frame
  std::vector<ModelObject> objects;  ///< one per request, in request order
};

/// Reads `modelFile` (at most kMaxMeshBytes); sceneFile and meshField name the scene key that
/// points at it. Errors: what scene/gltf_check.h refuses in a glTF level (its files outside its
/// folder or fetched from a network, its limits, glTF 2.0's rules, modes other than triangles,
/// formats assimp misreads, broken animation samplers, zero rotations), a file assimp cannot
/// read (one line of its message), a coordinate that is NaN, infinite or beyond the coordinate
/// limit, an FBX unit scale that is not positive, a requested node missing or named twice, or
/// whose transform has no rotation (a zero scale), an animation that moves a node no request
/// names, a rotation key of zero length, CUBICSPLINE interpolation, an animated scale.
RawModel readModel(const std::string& sceneFile, const std::string& modelFile,
                   const std::string& meshField, const std::vector<ModelObjectRequest>& requests);

}  // namespace dpc
