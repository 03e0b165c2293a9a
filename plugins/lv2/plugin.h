// The state of one "dpc room" instance, shared by the LV2 entry points (dpc_lv2.cpp) and the
// background loading of scenes (loader.cpp). Which thread touches which member is said at each.
#pragma once

#include <lv2/atom/forge.h>
#include <lv2/log/logger.h>
#include <lv2/urid/urid.h>
#include <lv2/worker/worker.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "dpc/dpc.h"
#include "plugins/lv2/host.h"

namespace dpc::lv2 {

constexpr const char* kSceneParam = "urn:dpc:lv2:room#scene";
/// The scene shipped inside the bundle.
constexpr const char* kDefaultScene = "scene/room.json";
/// Longest scene path the worker message carries, bytes.
constexpr size_t kMaxPath = 2048;

enum Port : uint32_t {
  kIn = 0,
  kOutL,
  kOutR,
  kListenerX,
  kListenerY,
  kListenerZ,
  kListenerYaw,
  kSourceX,
  kSourceY,
  kSourceZ,
  kControl,
  kNotify,
  kLatency,
  kPortCount
};

/// A loaded scene: the engine and the input pointer array process() needs (one per source,
/// all fed by the mono input). Built and freed off the audio thread.
struct Scene {
  dpc_engine* engine = nullptr;
  std::string path;
  bool isDefault = false;
  int channels = 0;
  std::vector<const float*> inputs;
  ~Scene() { dpc_engine_destroy(engine); }
};

/// A control port's declared range and default (dpc.ttl's lv2:minimum, lv2:maximum and
/// lv2:default; tests/lv2/lv2_test.py checks that both say the same).
struct PortRange {
  const char* symbol;
  float min, max, fallback;
};

/// The pose ports kListenerX..kSourceZ, in port order.
constexpr PortRange kPoseRanges[] = {
    {"listener_x", -100.f, 100.f, 7.f},  {"listener_y", -100.f, 100.f, 1.6f},
    {"listener_z", -100.f, 100.f, 3.5f}, {"listener_yaw", -180.f, 180.f, 180.f},
    {"source_x", -100.f, 100.f, 3.f},    {"source_y", -100.f, 100.f, 1.6f},
    {"source_z", -100.f, 100.f, 3.5f}};
constexpr int kPosePorts = int(sizeof kPoseRanges / sizeof kPoseRanges[0]);
static_assert(kListenerX + kPosePorts == kSourceZ + 1, "one range per pose port");

/// `v` within the port's range: the nearest bound beyond it, the default for NaN.
inline float clampToPort(const PortRange& r, float v) {
  return std::isnan(v) ? r.fallback : std::clamp(v, r.min, r.max);
}

/// Listener x, y, z (m), yaw (degrees); source x, y, z (m).
struct Pose {
  float v[kPosePorts];
  bool operator!=(const Pose& o) const { return std::memcmp(v, o.v, sizeof v) != 0; }
};

struct Uris {
  LV2_URID atomPath, atomUrid, atomObject, atomSequence, patchSet, patchGet, patchProperty,
      patchValue, sceneParam;
  void map(LV2_URID_Map* m);
};

struct Plugin {
  // Set by instantiate, read-only afterwards (any thread).
  double rate = 48000.0;
  /// The host's nominal block length (bufsz:nominalBlockLength), frames; 0 if not given. The
  /// engine block is set to it, so that every run() of that length does one block's work
  /// instead of a whole larger block inside one callback now and then.
  int hostBlock = 0;
  std::string bundle;
  LV2_URID_Map* map = nullptr;
  LV2_Worker_Schedule* schedule = nullptr;  ///< nullptr: an offline host (lv2apply)
  LV2_Log_Logger logger{};
  Uris uris{};
  const Variant* variant = &kVariants[0];

  // The audio thread's (and connect_port's, activate's, deactivate's: never concurrent).
  LV2_Atom_Forge forge{};
  void* ports[kPortCount] = {};
  float* extraOutputs[kMaxOutputs - 2] = {};  ///< outputs 3.. (ports kPortCount...)
  Scene* scene = nullptr;    ///< the playing scene; nullptr until the first load is ready
  bool notifyScene = false;  ///< tell the host the scene path at the next run()
  Pose sent{};               ///< the pose last published to the engine
  bool sentValid = false;
  bool collectScheduled = false;  ///< a kCollect for `outgoing` is queued on the worker

  // Background loading (loader.h). A load runs on `loader`, a thread of the plugin's own, and
  // hands its scene over through `incoming`; run() swaps it in and hands the scene it replaces
  // back through `outgoing`, freed off the audio thread.
  std::mutex loaderMutex;  ///< non-audio threads: starting and joining loads, requestedPath
  std::thread loader;
  std::string requestedPath;                 ///< the newest load's scene
  std::atomic<uint64_t> loadGeneration{0};   ///< the newest load; an older one's result is dropped
  std::atomic<Scene*> incoming{nullptr};     ///< loaded, waiting for run()
  std::atomic<Scene*> outgoing{nullptr};     ///< replaced by run(), waiting to be freed
  std::atomic<float> latestPose[kPosePorts];  ///< the pose run() last saw, for a new scene
  /// Non-audio threads: `active` and starting or stopping engines, against the loader's
  /// hand-over of a started engine.
  std::mutex lifecycle;
  bool active = false;

  // The playing scene's path for save(), which LV2 may call concurrently with run(): a
  // seqlock (run() writes without waiting, save() retries until it reads a stable copy).
  // Empty for the bundle's default scene.
  std::atomic<uint32_t> pathSeq{0};
  char savedPath[kMaxPath] = {};

  // Pose ports whose value left the declared range: each is logged once, off the audio
  // thread (by the worker, or at deactivate and cleanup without one). clamped: the ports
  // seen out of range (bit i for kPoseRanges[i]), with the first such value; reported: those
  // logged.
  std::atomic<uint32_t> clamped{0};
  std::atomic<float> firstOutside[kPosePorts] = {};
  uint32_t reported = 0;

  Plugin();
  /// Whoever swaps the scene (run() or, in a host without a worker, activate() and restore()):
  /// records its path for save().
  void recordPath(const Scene& s);
  /// save(): a consistent copy of savedPath.
  std::string readPath() const;
  /// The raw value of pose port i (kPoseRanges order), its default if unconnected.
  float raw(int i) const {
    const void* port = ports[kListenerX + i];
    return port ? *static_cast<const float*>(port) : kPoseRanges[i].fallback;
  }
  /// The pose the ports ask for, each value clamped to its declared range.
  Pose pose() const {
    Pose q{};
    for (int i = 0; i < kPosePorts; ++i) q.v[i] = clampToPort(kPoseRanges[i], raw(i));
    return q;
  }
  /// Any thread, wait-free: `latestPose` as one Pose (fields of two consecutive poses may mix).
  Pose latest() const;
  /// Audio thread, wait-free: records the ports out of range for the first time; true if any.
  bool noteClamped();
};

/// Not the audio thread: logs each port clamped since the last call, once per instance.
void reportClamped(Plugin* p);

/// Any thread but the audio thread: the message of the last failed dpc call, logged after
/// `what` (the step that failed; nullptr when the message says it).
void logError(Plugin* p, const char* what);

/// Publishes a pose to an engine's selected listener and first source (wait-free; any thread).
/// The pose is within the ports' ranges (Plugin::pose), inside the scene's limits.
void publish(dpc_engine* e, const Pose& q);

}  // namespace dpc::lv2
