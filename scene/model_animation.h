// A model node's animation channel (assimp's aiNodeAnim) as dpc keyframes. Private to scene/
// (scene/model_reader.cpp); docs/scene-format.md "glTF and FBX levels" is the user's view.
//
// assimp 5.2 hands over every glTF sampler's keys as if LINEAR and reads CUBICSPLINE tangents
// as keys, so the interpolation of each glTF channel is read from the file's own JSON
// (readGltfNodes). LINEAR keys become keyframes as they are; STEP keys also get a
// keyframe holding the previous value kStepHoldSeconds before each key; CUBICSPLINE is refused.
//
// Control thread; allocates; throws InputError naming the model file and the channel.
#pragma once

#include <assimp/anim.h>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace dpc {

/// How far before a STEP key its hold keyframe lies, seconds: below one sample period at
/// 192 kHz, so no frame or block sees the ramp between the two.
inline constexpr double kStepHoldSeconds = 1e-6;

/// A rigid pose with a scale: world = position + rotation * (scale * local).
struct Trs {
  glm::vec3 position{0.f};
  glm::quat rotation{1.f, 0.f, 0.f, 0.f};
  glm::vec3 scale{1.f};
};

/// What assimp 5.2 loses of a glTF node: each animated path's sampler interpolation
/// ("LINEAR", "STEP", "CUBICSPLINE"; assimp fills the paths a file does not animate from the
/// node's matrix, so a path missing here is not animated), and the node's own translation,
/// rotation and scale as the file gives them (assimp gives a matrix, whose decomposition
/// rounds; absent for a node given by "matrix").
struct GltfNode {
  std::map<std::string, std::string> interpolation;
  std::optional<Trs> trs;
};

/// Per node name, from a glTF level's JSON (checked by checkGltfLevel). Empty for null (a file
/// that is not glTF).
std::map<std::string, GltfNode> readGltfNodes(const nlohmann::json& doc);

/// One node's channel with what it needs to be read.
struct NodeChannel {
  const aiNodeAnim* channel = nullptr;
  std::string animation;        ///< the animation's name, for errors
  double ticksPerSecond = 1.0;  ///< assimp's key time unit (glTF: 1000)
  /// The glTF node's entry (readGltfNodes); nullptr for other formats, whose keys assimp
  /// reads as they are.
  const GltfNode* gltf = nullptr;
  ObjectKeyframe rest;       ///< the node's own translation and rotation, for absent paths
  glm::vec3 restScale{1.f};  ///< the node's own scale, for an absent scale path
};

/// The node's keys in its parent's frame: union of the translation and rotation key times,
/// each channel interpolated at the others' times (linear, slerp), rotations normalised.
struct NodeKeys {
  std::vector<ObjectKeyframe> keys;
  glm::vec3 scale{1.f};  ///< the scale keys' one value (objects are rigid)
};

NodeKeys readNodeKeys(const NodeChannel& c, const std::string& file);

}  // namespace dpc
