// Poses across the C API: listeners (yaw, pitch, roll), sources (positions) and moving objects
// (glTF-order quaternions), all in the one frame dpc.h defines; wait-free for any thread.
#include <cmath>
#include <glm/gtc/quaternion.hpp>

#include "api/engine_handle.h"
#include "api/errors.h"
#include "scene/orientation.h"

namespace {

constexpr float kDegrees = 3.14159265358979323846f / 180.f;

using dpc::api::checkArgument;
using dpc::api::checkIndex;
using dpc::api::failFixed;

/// True if x, y and z lie within the scene's "position" limit; otherwise the thread's message
/// names the first coordinate outside it.
bool checkPosition(const char* function, float x, float y, float z) {
  return checkArgument(function, "x", "position", x) &&
         checkArgument(function, "y", "position", y) && checkArgument(function, "z", "position", z);
}

/// The norm of q = (x, y, z, w) in double (no overflow for any finite float), 0 if q holds a
/// non-finite value: a rotation needs a norm > 0.
double quaternionNorm(float qx, float qy, float qz, float qw) {
  const double n = std::sqrt(double(qx) * qx + double(qy) * qy + double(qz) * qz + double(qw) * qw);
  return std::isfinite(n) ? n : 0.0;
}

/// Both listener pose setters, after checking every argument against the scene's limits.
dpc_status setListenerPose(const char* function, dpc_engine* engine, int listener,
                           const glm::vec3& position, float yaw, float pitch, float roll) {
  if (!engine) return failFixed(DPC_ERR_INVALID_ARGUMENT, function, "engine is NULL");
  if (const dpc_status s = checkIndex(function, "listener", listener,
                                      dpc_engine_listener_count(engine), "listeners");
      s != DPC_OK)
    return s;
  if (!checkPosition(function, position.x, position.y, position.z) ||
      !checkArgument(function, "yaw_degrees", "listener.yaw", yaw) ||
      !checkArgument(function, "pitch_degrees", "listener.pitch", pitch) ||
      !checkArgument(function, "roll_degrees", "listener.roll", roll))
    return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->setListenerPose(size_t(listener), position, yaw * kDegrees, 0.0,
                                          pitch * kDegrees, roll * kDegrees)
             ? DPC_OK
             : failFixed(DPC_ERR_INVALID_ARGUMENT, function, "pose refused");
}

/// Yaw, pitch and roll (degrees) of the listener turned by q = (x, y, z, w), normalised here
/// (dpc.h, dpc_yaw_pitch_roll_from_quaternion).
dpc_status anglesFromQuaternion(const char* function, float qx, float qy, float qz, float qw,
                                float* yaw, float* pitch, float* roll) {
  if (!yaw || !pitch || !roll)
    return failFixed(DPC_ERR_INVALID_ARGUMENT, function, "an output pointer is NULL");
  const double norm = quaternionNorm(qx, qy, qz, qw);
  if (!(norm > 0.0))
    return failFixed(DPC_ERR_INVALID_ARGUMENT, function, "q is zero or not finite");
  const glm::quat q(float(qw / norm), float(qx / norm), float(qy / norm), float(qz / norm));
  const dpc::Orientation o =
      dpc::orientationFromAxes(q * glm::vec3(1.f, 0.f, 0.f), q * glm::vec3(0.f, 1.f, 0.f));
  *yaw = o.yawRadians / kDegrees;
  *pitch = o.pitchRadians / kDegrees;
  *roll = o.rollRadians / kDegrees;
  return DPC_OK;
}

}  // namespace

// Any thread: failures set the thread's message in its fixed buffer (api/errors.h), without
// allocating.
extern "C" {

int dpc_engine_listener_count(const dpc_engine* engine) {
  return engine ? int(engine->session->listenerCount()) : 0;
}

dpc_status dpc_engine_set_listener_pose(dpc_engine* engine, int listener, float x, float y, float z,
                                        float yaw_degrees, float pitch_degrees) {
  return setListenerPose("dpc_engine_set_listener_pose", engine, listener, glm::vec3(x, y, z),
                         yaw_degrees, pitch_degrees, 0.f);
}

dpc_status dpc_engine_set_listener_head_pose(dpc_engine* engine, int listener, float x, float y,
                                             float z, float yaw_degrees, float pitch_degrees,
                                             float roll_degrees) {
  return setListenerPose("dpc_engine_set_listener_head_pose", engine, listener, glm::vec3(x, y, z),
                         yaw_degrees, pitch_degrees, roll_degrees);
}

dpc_status dpc_engine_select_listener(dpc_engine* engine, int listener) {
  constexpr const char* kFunction = "dpc_engine_select_listener";
  if (!engine) return failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "engine is NULL");
  if (const dpc_status s = checkIndex(kFunction, "listener", listener,
                                      dpc_engine_listener_count(engine), "listeners");
      s != DPC_OK)
    return s;
  return engine->session->selectListener(size_t(listener))
             ? DPC_OK
             : failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "listener refused");
}

int dpc_engine_selected_listener(const dpc_engine* engine) {
  return engine ? int(engine->session->playedListener()) : 0;
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
  constexpr const char* kFunction = "dpc_engine_set_source_position";
  if (!engine) return failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "engine is NULL");
  if (const dpc_status s = checkIndex(kFunction, "source", source, engine->sources, "sources");
      s != DPC_OK)
    return s;
  if (!checkPosition(kFunction, x, y, z)) return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->setSourcePosition(size_t(source), glm::vec3(x, y, z))
             ? DPC_OK
             : failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "position refused");
}

dpc_status dpc_engine_teleport_source(dpc_engine* engine, int source) {
  constexpr const char* kFunction = "dpc_engine_teleport_source";
  if (!engine) return failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "engine is NULL");
  if (const dpc_status s = checkIndex(kFunction, "source", source, engine->sources, "sources");
      s != DPC_OK)
    return s;
  engine->session->teleportSource(size_t(source));
  return DPC_OK;
}

dpc_status dpc_engine_teleport_listener(dpc_engine* engine, int listener) {
  constexpr const char* kFunction = "dpc_engine_teleport_listener";
  if (!engine) return failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "engine is NULL");
  if (const dpc_status s = checkIndex(kFunction, "listener", listener,
                                      dpc_engine_listener_count(engine), "listeners");
      s != DPC_OK)
    return s;
  engine->session->teleportListener(size_t(listener));
  return DPC_OK;
}

dpc_status dpc_engine_set_source_rotation(dpc_engine* engine, int source, float qx, float qy,
                                          float qz, float qw) {
  constexpr const char* kFunction = "dpc_engine_set_source_rotation";
  if (!engine) return failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "engine is NULL");
  if (const dpc_status s = checkIndex(kFunction, "source", source, engine->sources, "sources");
      s != DPC_OK)
    return s;
  const float q[4] = {qx, qy, qz, qw};
  return engine->session->setSourceRotation(size_t(source), q)
             ? DPC_OK
             : failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "q is zero or not finite");
}

dpc_status dpc_engine_set_object_pose(dpc_engine* engine, int object, float x, float y, float z,
                                      float qx, float qy, float qz, float qw) {
  constexpr const char* kFunction = "dpc_engine_set_object_pose";
  if (!engine) return failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "engine is NULL");
  if (const dpc_status s = checkIndex(kFunction, "object", object, dpc_engine_object_count(engine),
                                      "moving objects");
      s != DPC_OK)
    return s;
  if (!checkPosition(kFunction, x, y, z)) return DPC_ERR_INVALID_ARGUMENT;
  // Index and position are checked: the session refuses only a rotation it cannot normalise.
  const float q[4] = {qx, qy, qz, qw};
  return engine->session->setObjectPose(size_t(object), glm::vec3(x, y, z), q)
             ? DPC_OK
             : failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "q is zero or not finite");
}

}  // extern "C"
