// Poses across the C API: listeners (yaw and pitch), sources (positions) and moving objects
// (glTF-order quaternions), all in the one frame dpc.h defines; wait-free for any thread.
#include <cmath>
#include <glm/gtc/quaternion.hpp>

#include "api/engine_handle.h"

namespace {

constexpr float kDegrees = 3.14159265358979323846f / 180.f;

bool allFinite(std::initializer_list<float> values) {
  for (float v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace

// Any thread: no message is set on failure in this file (setting one would allocate).
extern "C" {

int dpc_engine_listener_count(const dpc_engine* engine) {
  return engine ? int(engine->session->listenerCount()) : 0;
}

dpc_status dpc_engine_set_listener_pose(dpc_engine* engine, int listener, float x, float y,
                                        float z, float yaw_degrees, float pitch_degrees) {
  if (!engine || listener < 0 || !allFinite({x, y, z, yaw_degrees, pitch_degrees}))
    return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->setListenerPose(size_t(listener), glm::vec3(x, y, z),
                                          yaw_degrees * kDegrees, 0.0, pitch_degrees * kDegrees)
             ? DPC_OK
             : DPC_ERR_INVALID_ARGUMENT;
}

dpc_status dpc_engine_select_listener(dpc_engine* engine, int listener) {
  if (!engine || listener < 0) return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->selectListener(size_t(listener)) ? DPC_OK : DPC_ERR_INVALID_ARGUMENT;
}

int dpc_engine_selected_listener(const dpc_engine* engine) {
  return engine ? int(engine->session->playedListener()) : 0;
}

dpc_status dpc_yaw_pitch_from_quaternion(float qx, float qy, float qz, float qw,
                                         float* yaw_degrees, float* pitch_degrees) {
  if (!yaw_degrees || !pitch_degrees || !allFinite({qx, qy, qz, qw}))
    return DPC_ERR_INVALID_ARGUMENT;
  const glm::quat q(qw, qx, qy, qz);
  const float norm = glm::length(q);
  if (!(norm > 0.f) || !std::isfinite(norm)) return DPC_ERR_INVALID_ARGUMENT;
  const glm::vec3 f = (q / norm) * glm::vec3(1.f, 0.f, 0.f);
  const float horizontal = std::hypot(f.x, f.z);
  *yaw_degrees = horizontal > 0.f ? std::atan2(-f.z, f.x) / kDegrees : 0.f;
  *pitch_degrees = std::atan2(f.y, horizontal) / kDegrees;
  return DPC_OK;
}

dpc_status dpc_engine_set_source_position(dpc_engine* engine, int source, float x, float y,
                                          float z) {
  if (!engine || source < 0 || source >= engine->sources || !allFinite({x, y, z}))
    return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->setSourcePosition(size_t(source), glm::vec3(x, y, z))
             ? DPC_OK
             : DPC_ERR_INVALID_ARGUMENT;
}

dpc_status dpc_engine_set_object_pose(dpc_engine* engine, int object, float x, float y, float z,
                                      float qx, float qy, float qz, float qw) {
  if (!engine || object < 0 || object >= engine->session->objectCount() ||
      !allFinite({x, y, z, qx, qy, qz, qw}))
    return DPC_ERR_INVALID_ARGUMENT;
  const float q[4] = {qx, qy, qz, qw};
  return engine->session->setObjectPose(size_t(object), glm::vec3(x, y, z), q)
             ? DPC_OK
             : DPC_ERR_INVALID_ARGUMENT;
}

}  // extern "C"
