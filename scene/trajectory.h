// Trajectory evaluation: where the scene's listeners, sources and objects are at a time
// (keyframes interpolated linearly, rotations slerped along the shorter arc, clamped at the ends
// or wrapped when looping, held before a teleport keyframe), everything that moves gathered into
// one WorldState, and the teleports between two times.
//
// Threads: any thread (the scene is read only). Allocation: none, except evaluateWorld and
// markTeleports, which grow the state's vectors. Errors: none.
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "scene/orientation.h"
#include "scene/scene.h"

namespace dpc {

/// Listener position at time t (seconds) along the trajectory (linear interpolation,
/// clamped at the ends, or wrapped when loop is set). Any thread; no allocation.
glm::vec3 listenerPositionAt(const ListenerDesc& listener, double t);

/// Listener orientation at time t: the keyframes' yaw/pitch interpolated (yaw along the
/// shorter arc), or facing the direction of motion along the trajectory (the last direction of
/// motion while standing), or listener.yawDegrees without a trajectory. Any thread.
Orientation listenerOrientationAt(const ListenerDesc& listener, double t);

/// Source position at time t: its trajectory as listenerPositionAt (linear, clamped or
/// wrapped), or its fixed position. Any thread; no allocation.
glm::vec3 sourcePositionAt(const SourceDesc& source, double t);

/// Source orientation at time t: the keyframes' rotations slerped (shorter arc; clamped or
/// wrapped as the position), or source.rotation when they give none. Any thread; no allocation.
glm::quat sourceRotationAt(const SourceDesc& source, double t);

/// Object pose at time t: position linear, rotation slerped (shorter arc) between keyframes,
/// clamped at the ends or wrapped when loop is set. Any thread; no allocation.
Pose objectPoseAt(const ObjectDesc& object, double t);

/// Everything that moves, evaluated at one time: one entry per scene listener, source and
/// object, in scene order (docs/design.md, "Runtime interfaces that several features share").
struct WorldState {
  double timeSeconds = 0.0;
  std::vector<glm::vec3> listenerPositions;  ///< metres
  std::vector<Orientation> listenerOrientations;
  std::vector<glm::vec3> sourcePositions;  ///< metres
  std::vector<glm::quat> sourceRotations;  ///< unit quaternions (sourceRotationAt)
  std::vector<Pose> objectPoses;
  /// Per source and per listener: 1 when it jumped (a "teleport" keyframe, or a host's
  /// teleport call) since the previous frame's world, so that its pairs' caches start over.
  std::vector<uint8_t> sourceTeleports, listenerTeleports;
};

/// Whether the keyframes hold a teleport keyframe whose time lies in (from, to] seconds (every
/// period of a looping trajectory counts). Any thread; no allocation.
bool teleportBetween(const std::vector<Keyframe>& keys, bool loop, double from, double to);

/// Sets world.sourceTeleports and listenerTeleports for the scene's trajectories between the
/// times from and to (seconds; teleportBetween). Allocates only when the vectors grow.
void markTeleports(const SceneDesc& scene, double from, double to, WorldState& world);

/// Evaluates every trajectory of the scene at time t, with the teleports between the state's
/// previous time and t (markTeleports). Allocates only when `state`'s vectors grow. Any
/// thread (the scene is read only).
void evaluateWorld(const SceneDesc& scene, double t, WorldState& state);

}  // namespace dpc
