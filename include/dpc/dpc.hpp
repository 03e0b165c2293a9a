// C++ façade over the C API (include/dpc/dpc.h): RAII engine, errors as dpc::Error exceptions
// on the control thread, standard-library types only. Thread roles, units, allocation and
// errors are those of the C function each method calls (see dpc.h).
#pragma once

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "dpc/dpc.h"

namespace dpc {

/// A failed control-thread call: the dpc_status and the library's one-line message.
class Error : public std::runtime_error {
 public:
  Error(dpc_status status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  dpc_status status() const noexcept { return status_; }

 private:
  dpc_status status_;
};

using Stats = dpc_stats;
using Pose = dpc_pose;

class Engine {
 public:
  /// Control thread; allocates; throws dpc::Error naming the scene file and field. options
  /// (filled by dpc_engine_options_init first) may be nullptr: the scene's settings.
  static Engine fromFile(const std::string& scenePath,
                         const dpc_engine_options* options = nullptr) {
    dpc_engine* e = nullptr;
    check(dpc_engine_create_from_file(scenePath.c_str(), options, &e));
    return Engine(e);
  }
  /// Control thread: a scene built in code (dpc_scene_data, filled by dpc_scene_data_init
  /// first); throws dpc::Error naming the field. options may be nullptr.
  static Engine fromData(const dpc_scene_data& data, const dpc_engine_options* options = nullptr) {
    dpc_engine* e = nullptr;
    check(dpc_engine_create_from_data(&data, options, &e));
    return Engine(e);
  }
  Engine(Engine&& o) noexcept : e_(std::exchange(o.e_, nullptr)) {}
  Engine& operator=(Engine&& o) noexcept {
    std::swap(e_, o.e_);
    return *this;
  }
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;
  ~Engine() { dpc_engine_destroy(e_); }

  /// Control thread: start/stop the propagation thread (idempotent).
  void start() { check(dpc_engine_start(e_)); }
  void stop() { check(dpc_engine_stop(e_)); }

  /// Any thread: listeners traced every frame (dpc_engine_listener_count).
  int listenerCount() const noexcept { return dpc_engine_listener_count(e_); }
  /// Any thread, wait-free: places a listener, a source or a moving object (position in
  /// metres, rotation quaternion x, y, z, w; dpc_engine_place_listener, _source, _object in
  /// dpc/dpc_poses.h). Return the status instead of throwing so that they may be called from an
  /// audio thread.
  dpc_status placeListener(int listener, const dpc_pose& pose) noexcept {
    return dpc_engine_place_listener(e_, listener, &pose);
  }
  dpc_status placeSource(int source, const dpc_pose& pose) noexcept {
    return dpc_engine_place_source(e_, source, &pose);
  }
  dpc_status placeObject(int object, const dpc_pose& pose) noexcept {
    return dpc_engine_place_object(e_, object, &pose);
  }
  /// Any thread, wait-free: pose of listener `listener` (dpc_engine_set_listener_pose):
  /// position (m), yaw and pitch (degrees, the frame of dpc.h). Returns the status instead of
  /// throwing so that it may be called from an audio thread.
  dpc_status setListenerPose(int listener, float x, float y, float z, float yawDegrees,
                             float pitchDegrees = 0.f, float rollDegrees = 0.f) noexcept {
    return dpc_engine_set_listener_head_pose(e_, listener, x, y, z, yawDegrees, pitchDegrees,
                                             rollDegrees);
  }
  /// Any thread, wait-free: the listener heard and read out (dpc_engine_select_listener).
  dpc_status selectListener(int listener) noexcept {
    return dpc_engine_select_listener(e_, listener);
  }
  int selectedListener() const noexcept { return dpc_engine_selected_listener(e_); }

  /// Any thread, wait-free: see dpc_engine_set_source_position (metres).
  dpc_status setSourcePosition(int source, float x, float y, float z) noexcept {
    return dpc_engine_set_source_position(e_, source, x, y, z);
  }
  /// Any thread, wait-free: see dpc_engine_teleport_source and dpc_engine_teleport_listener.
  dpc_status teleportSource(int source) noexcept { return dpc_engine_teleport_source(e_, source); }
  dpc_status teleportListener(int listener) noexcept {
    return dpc_engine_teleport_listener(e_, listener);
  }
  /// Any thread, wait-free: see dpc_engine_set_source_rotation (quaternion x, y, z, w).
  dpc_status setSourceRotation(int source, float qx, float qy, float qz, float qw) noexcept {
    return dpc_engine_set_source_rotation(e_, source, qx, qy, qz, qw);
  }
  /// Any thread, wait-free: see dpc_engine_set_object_pose (metres, quaternion x, y, z, w).
  dpc_status setObjectPose(int object, float x, float y, float z, float qx, float qy, float qz,
                           float qw) noexcept {
    return dpc_engine_set_object_pose(e_, object, x, y, z, qx, qy, qz, qw);
  }

  /// Audio thread: see dpc_engine_process. Never allocates or throws.
  dpc_status process(const float* const* inputs, float* const* outputs, int frames) noexcept {
    return dpc_engine_process(e_, inputs, outputs, frames);
  }

  int sampleRate() const noexcept { return dpc_engine_sample_rate(e_); }          ///< Hz
  int blockSize() const noexcept { return dpc_engine_block_size(e_); }            ///< frames
  /// Channels process() writes (dpc_engine_output_channels).
  int outputChannels() const noexcept { return dpc_engine_output_channels(e_); }
  /// Channels of impulseResponse() (dpc_engine_ir_channels).
  int irChannels() const noexcept { return dpc_engine_ir_channels(e_); }
  int sourceCount() const noexcept { return dpc_engine_source_count(e_); }
  int objectCount() const noexcept { return dpc_engine_object_count(e_); }
  int latencyFrames() const noexcept { return dpc_engine_latency_frames(e_); }  ///< frames

  /// Control thread, engine stopped: one propagation frame now (dpc_engine_step).
  void step() { check(dpc_engine_step(e_)); }

  /// Not the audio thread: the newest impulse response of `source`, channel `channel`
  /// (linear pressure at sampleRate()). Allocates the vector; throws dpc::Error before the
  /// first frame.
  std::vector<float> impulseResponse(int source, int channel) {
    size_t n = 0;
    check(dpc_engine_copy_impulse_response(e_, source, channel, nullptr, 0, &n, nullptr));
    std::vector<float> ir(n);
    size_t copied = 0;
    check(dpc_engine_copy_impulse_response(e_, source, channel, ir.data(), n, &copied, nullptr));
    ir.resize(std::min(n, copied));  // a later frame could be shorter, never with one scene
    return ir;
  }
  /// Not the audio thread: the newest energy response of `source`, bin-major
  /// [bin * DPC_BANDS + band], 1/m^2 per binSeconds (1 ms) bin.
  std::vector<float> energyResponse(int source, double* binSeconds = nullptr) {
    size_t bins = 0;
    check(dpc_engine_copy_energy_response(e_, source, nullptr, 0, &bins, binSeconds, nullptr));
    std::vector<float> er(bins * DPC_BANDS);
    check(dpc_engine_copy_energy_response(e_, source, er.data(), bins, nullptr, nullptr, nullptr));
    return er;
  }

  /// Control thread: counters and last-frame measurements.
  Stats stats() {
    Stats s{};
    s.struct_size = sizeof(Stats);
    check(dpc_engine_get_stats(e_, &s));
    return s;
  }

  dpc_engine* handle() noexcept { return e_; }

 private:
  explicit Engine(dpc_engine* e) : e_(e) {}
  static void check(dpc_status s) {
    if (s != DPC_OK) throw Error(s, dpc_last_error());
  }
  dpc_engine* e_ = nullptr;
};

}  // namespace dpc
