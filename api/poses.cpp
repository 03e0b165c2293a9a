// Poses across the C API (include/dpc/dpc_poses.h): one dpc_pose for listeners, sources and
// moving objects, and the setters of 0.2.0 to 0.6.0 over the same checks and channels, all in
// the one frame dpc_poses.h defines; wait-free for any thread.
#include <glm/gtc/quaternion.hpp>
#include <optional>

#include "api/engine_handle.h"
#include "api/errors.h"
#include "common/text_buffer.h"
#include "scene/quaternion.h"
#include "scene/scene.h"

namespace {

constexpr float kDegrees = 3.14159265358979323846f / 180.f;

using dpc::api::checkArgument;
using dpc::api::checkIndex;
using dpc::api::EngineCall;
using dpc::api::failFixed;

/// How a setter names a pose's parts in its messages: the pose struct's fields, or the
/// separate arguments of the setters of 0.2.0 to 0.6.0.
struct PoseNames {
  const char* position[3];
  const char* rotation;
};
constexpr PoseNames kPoseFields{{"pose.position[0]", "pose.position[1]", "pose.position[2]"},
                                "pose.rotation"};
constexpr PoseNames kArguments{{"x", "y", "z"}, "q"};

/// What a source setter changes.
enum SourceParts { kPosition = 1, kRotation = 2 };

glm::vec3 vec3(const float* p) {
  return glm::vec3(p[0], p[1], p[2]);
}

/// True if each coordinate lies within the scene's "position" limit; otherwise the thread's
/// message names the first one outside it.
bool checkPosition(const char* function, const PoseNames& names, const float position[3]) {
  for (int i = 0; i < 3; ++i)
    if (!checkArgument(function, names.position[i], "position", position[i])) return false;
  return true;
}

/// q (x, y, z, w) normalised (scene/quaternion.h), or nullopt with "FUNCTION: NAME is zero or
/// not finite" as the thread's message.
std::optional<glm::quat> checkRotation(const char* function, const PoseNames& names,
                                       const float q[4]) {
  const std::optional<glm::quat> unit = dpc::unitQuaternion(q[0], q[1], q[2], q[3]);
  if (!unit) {
    char problem[64];
    dpc::TextBuffer(problem, sizeof problem) << names.rotation << " is zero or not finite";
    failFixed(DPC_ERR_INVALID_ARGUMENT, function, problem);
  }
  return unit;
}

/// The listener orientation of a rotation of its rest pose (facing +x, +y up).
dpc::Orientation listenerOrientation(const glm::quat& q) {
  return dpc::orientationFromAxes(q * glm::vec3(1.f, 0.f, 0.f), q * glm::vec3(0.f, 1.f, 0.f));
}

/// Listener `listener`'s index checked, then its checked pose published.
dpc_status publishListener(const char* function, dpc_engine& engine, int listener,
                           const glm::vec3& position, const dpc::Orientation& o) {
  return engine.session->setListenerPose(size_t(listener), position, o.yawRadians, 0.0,
                                         o.pitchRadians, o.rollRadians)
             ? DPC_OK
             : failFixed(DPC_ERR_INVALID_ARGUMENT, function, "pose refused");
}

dpc_status checkListener(const char* function, const dpc_engine& engine, int listener) {
  return checkIndex(function, "listener", listener, int(engine.session->listenerCount()),
                    "listeners");
}

/// The listener setters of 0.2.0 and 0.5.0: yaw, pitch and roll in degrees, each checked
/// against the scene's limits.
dpc_status setListenerAngles(const char* function, dpc_engine* engine, int listener,
                             const float position[3], float yaw, float pitch, float roll) {
  const EngineCall call(engine);
  if (const dpc_status s = call.check(function); s != DPC_OK) return s;
  if (const dpc_status s = checkListener(function, *engine, listener); s != DPC_OK) return s;
  if (!checkPosition(function, kArguments, position) ||
      !checkArgument(function, "yaw_degrees", "listener.yaw", yaw) ||
      !checkArgument(function, "pitch_degrees", "listener.pitch", pitch) ||
      !checkArgument(function, "roll_degrees", "listener.roll", roll))
    return DPC_ERR_INVALID_ARGUMENT;
  return publishListener(function, *engine, listener, vec3(position),
                         dpc::Orientation{yaw * kDegrees, pitch * kDegrees, roll * kDegrees});
}

/// Source `source`'s position, rotation or both from `pose`; every part it changes is checked
/// before any is published. The session normalises the rotation itself (once, as a file's).
dpc_status placeSource(const char* function, const PoseNames& names, dpc_engine* engine,
                       int source, const dpc_pose* pose, int parts) {
  const EngineCall call(engine);
  if (const dpc_status s = call.check(function); s != DPC_OK) return s;
  if (!pose) return failFixed(DPC_ERR_INVALID_ARGUMENT, function, "pose is NULL");
  if (const dpc_status s = checkIndex(function, "source", source, engine->sources, "sources");
      s != DPC_OK)
    return s;
  if ((parts & kPosition) && !checkPosition(function, names, pose->position))
    return DPC_ERR_INVALID_ARGUMENT;
  if ((parts & kRotation) && !checkRotation(function, names, pose->rotation))
    return DPC_ERR_INVALID_ARGUMENT;
  bool published = true;
  if (parts & kPosition)
    published = engine->session->setSourcePosition(size_t(source), vec3(pose->position));
  if (parts & kRotation)
    published = engine->session->setSourceRotation(size_t(source), pose->rotation) && published;
  return published ? DPC_OK : failFixed(DPC_ERR_INVALID_ARGUMENT, function, "pose refused");
}

/// Moving object `object` at `pose`, position and rotation checked first (the session
/// normalises the rotation).
dpc_status placeObject(const char* function, const PoseNames& names, dpc_engine* engine,
                       int object, const dpc_pose* pose) {
  const EngineCall call(engine);
  if (const dpc_status s = call.check(function); s != DPC_OK) return s;
  if (!pose) return failFixed(DPC_ERR_INVALID_ARGUMENT, function, "pose is NULL");
  if (const dpc_status s = checkIndex(function, "object", object,
                                      engine->session->objectCount(), "moving objects");
      s != DPC_OK)
    return s;
  if (!checkPosition(function, names, pose->position) ||
      !checkRotation(function, names, pose->rotation))
    return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->setObjectPose(size_t(object), vec3(pose->position), pose->rotation)
             ? DPC_OK
             : failFixed(DPC_ERR_INVALID_ARGUMENT, function, "pose refused");
}

/// Yaw, pitch and roll (degrees) of the listener turned by q = (x, y, z, w), normalised here
/// (dpc_poses.h, dpc_yaw_pitch_roll_from_quaternion).
dpc_status anglesFromQuaternion(const char* function, float qx, float qy, float qz, float qw,
                                float* yaw, float* pitch, float* roll) {
  if (!yaw || !pitch || !roll)
    return failFixed(DPC_ERR_INVALID_ARGUMENT, function, "an output pointer is NULL");
  const float q[4] = {qx, qy, qz, qw};
  const std::optional<glm::quat> unit = checkRotation(function, kArguments, q);
  if (!unit) return DPC_ERR_INVALID_ARGUMENT;
  const dpc::Orientation o = listenerOrientation(*unit);
  *yaw = o.yawRadians / kDegrees;
  *pitch = o.pitchRadians / kDegrees;
  *roll = o.rollRadians / kDegrees;
  return DPC_OK;
}

}  // namespace

// Any thread: failures set the thread's message in its fixed buffer (api/errors.h), without
// allocating.
extern "C" {

dpc_status dpc_engine_place_listener(dpc_engine* engine, int listener, const dpc_pose* pose) {
  constexpr const char* kFunction = "dpc_engine_place_listener";
  const EngineCall call(engine);
  if (const dpc_status s = call.check(kFunction); s != DPC_OK) return s;
  if (!pose) return failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "pose is NULL");
  if (const dpc_status s = checkListener(kFunction, *engine, listener); s != DPC_OK) return s;
  if (!checkPosition(kFunction, kPoseFields, pose->position)) return DPC_ERR_INVALID_ARGUMENT;
  const std::optional<glm::quat> q = checkRotation(kFunction, kPoseFields, pose->rotation);
  if (!q) return DPC_ERR_INVALID_ARGUMENT;
  return publishListener(kFunction, *engine, listener, vec3(pose->position),
                         listenerOrientation(*q));
}

dpc_status dpc_engine_place_source(dpc_engine* engine, int source, const dpc_pose* pose) {
  return placeSource("dpc_engine_place_source", kPoseFields, engine, source, pose,
                     kPosition | kRotation);
}

dpc_status dpc_engine_place_object(dpc_engine* engine, int object, const dpc_pose* pose) {
  return placeObject("dpc_engine_place_object", kPoseFields, engine, object, pose);
}

int dpc_engine_listener_count(const dpc_engine* engine) {
  return dpc::api::engineProperty(
      engine, [](const dpc_engine& e) { return int(e.session->listenerCount()); });
}

dpc_status dpc_engine_set_listener_pose(dpc_engine* engine, int listener, float x, float y, float z,
                                        float yaw_degrees, float pitch_degrees) {
  const float position[3] = {x, y, z};
  return setListenerAngles("dpc_engine_set_listener_pose", engine, listener, position,
                           yaw_degrees, pitch_degrees, 0.f);
}

dpc_status dpc_engine_set_listener_head_pose(dpc_engine* engine, int listener, float x, float y,
                                             float z, float yaw_degrees, float pitch_degrees,
                                             float roll_degrees) {
  const float position[3] = {x, y, z};
  return setListenerAngles("dpc_engine_set_listener_head_pose", engine, listener, position,
                           yaw_degrees, pitch_degrees, roll_degrees);
}

dpc_status dpc_engine_select_listener(dpc_engine* engine, int listener) {
  constexpr const char* kFunction = "dpc_engine_select_listener";
  const EngineCall call(engine);
  if (const dpc_status s = call.check(kFunction); s != DPC_OK) return s;
  if (const dpc_status s = checkListener(kFunction, *engine, listener); s != DPC_OK) return s;
  return engine->session->selectListener(size_t(listener))
             ? DPC_OK
             : failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "listener refused");
}

int dpc_engine_selected_listener(const dpc_engine* engine) {
  return dpc::api::engineProperty(
      engine, [](const dpc_engine& e) { return int(e.session->playedListener()); });
}

dpc_status dpc_yaw_pitch_from_quaternion(float qx, float qy, float qz, float qw, float* yaw_degrees,
                                         float* pitch_degrees) {
  float roll = 0.f;
  return anglesFromQuaternion("dpc_yaw_pitch_from_quaternion", qx, qy, qz, qw, yaw_degrees,
                              pitch_degrees, &roll);
}

dpc_status dpc_yaw_pitch_roll_from_quaternion(float qx, float qy, float qz, float qw,
                                              float* yaw_degrees, float* pitch_degrees,
                                              float* roll_degrees) {
  return anglesFromQuaternion("dpc_yaw_pitch_roll_from_quaternion", qx, qy, qz, qw, yaw_degrees,
                              pitch_degrees, roll_degrees);
}

dpc_status dpc_engine_set_source_position(dpc_engine* engine, int source, float x, float y,
                                          float z) {
  const dpc_pose pose{{x, y, z}, {0.f, 0.f, 0.f, 1.f}};
  return placeSource("dpc_engine_set_source_position", kArguments, engine, source, &pose,
                     kPosition);
}

dpc_status dpc_engine_teleport_source(dpc_engine* engine, int source) {
  constexpr const char* kFunction = "dpc_engine_teleport_source";
  const EngineCall call(engine);
  if (const dpc_status s = call.check(kFunction); s != DPC_OK) return s;
  if (const dpc_status s = checkIndex(kFunction, "source", source, engine->sources, "sources");
      s != DPC_OK)
    return s;
  engine->session->teleportSource(size_t(source));
  return DPC_OK;
}

dpc_status dpc_engine_teleport_listener(dpc_engine* engine, int listener) {
  constexpr const char* kFunction = "dpc_engine_teleport_listener";
  const EngineCall call(engine);
  if (const dpc_status s = call.check(kFunction); s != DPC_OK) return s;
  if (const dpc_status s = checkListener(kFunction, *engine, listener); s != DPC_OK) return s;
  engine->session->teleportListener(size_t(listener));
  return DPC_OK;
}

dpc_status dpc_engine_set_source_rotation(dpc_engine* engine, int source, float qx, float qy,
                                          float qz, float qw) {
  const dpc_pose pose{{0.f, 0.f, 0.f}, {qx, qy, qz, qw}};
  return placeSource("dpc_engine_set_source_rotation", kArguments, engine, source, &pose,
                     kRotation);
}

dpc_status dpc_engine_set_object_pose(dpc_engine* engine, int object, float x, float y, float z,
                                      float qx, float qy, float qz, float qw) {
  const dpc_pose pose{{x, y, z}, {qx, qy, qz, qw}};
  return placeObject("dpc_engine_set_object_pose", kArguments, engine, object, &pose);
}

}  // extern "C"
