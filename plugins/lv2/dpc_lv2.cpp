// LV2 plugin "dpc room": a mono dry input rendered through a dpc scene to a stereo (or
// binaural, if the scene says so) output. A thin layer over the public C API (include/dpc/dpc.h):
// one dpc_engine per loaded scene, whose propagation thread runs inside the instance; run() only
// publishes the control ports' poses (wait-free) and calls dpc_engine_process (no allocation,
// locks or waiting). Another scene is chosen through the patch:Parameter <URI#scene> (atom:Path),
// loaded by the LV2 worker and saved with the plugin's state (docs/design.md "LV2 plugin").
#include <lv2/atom/atom.h>
#include <lv2/atom/forge.h>
#include <lv2/atom/util.h>
#include <lv2/buf-size/buf-size.h>
#include <lv2/core/lv2.h>
#include <lv2/log/log.h>
#include <lv2/log/logger.h>
#include <lv2/options/options.h>
#include <lv2/patch/patch.h>
#include <lv2/state/state.h>
#include <lv2/urid/urid.h>
#include <lv2/worker/worker.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "dpc/dpc.h"
#include "plugins/lv2/host.h"

namespace {

using dpc::lv2::kMaxOutputs;
using dpc::lv2::Variant;

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
float clampToPort(const PortRange& r, float v) {
  return std::isnan(v) ? r.fallback : std::clamp(v, r.min, r.max);
}

/// Listener x, y, z (m), yaw (degrees); source x, y, z (m).
struct Pose {
  float v[7];
  bool operator!=(const Pose& o) const { return std::memcmp(v, o.v, sizeof v) != 0; }
};

/// Worker messages: load a scene (path follows), free one, or log the ports clamped so far.
struct WorkMessage {
  enum Kind : uint32_t { kLoad, kFree, kReportClamped } kind;
  Scene* scene;  ///< kFree
  Pose pose;     ///< kLoad: the pose to compute the first frame for
  bool start;    ///< kLoad: start the propagation thread (the plugin is active)
  char path[1];  ///< kLoad: NUL-terminated, the message's tail
};

struct Uris {
  LV2_URID atomPath, atomUrid, atomObject, atomSequence, patchSet, patchGet, patchProperty,
      patchValue, sceneParam;
  void map(LV2_URID_Map* m) {
    atomPath = m->map(m->handle, LV2_ATOM__Path);
    atomUrid = m->map(m->handle, LV2_ATOM__URID);
    atomObject = m->map(m->handle, LV2_ATOM__Object);
    atomSequence = m->map(m->handle, LV2_ATOM__Sequence);
    patchSet = m->map(m->handle, LV2_PATCH__Set);
    patchGet = m->map(m->handle, LV2_PATCH__Get);
    patchProperty = m->map(m->handle, LV2_PATCH__property);
    patchValue = m->map(m->handle, LV2_PATCH__value);
    sceneParam = m->map(m->handle, kSceneParam);
  }
};

struct Plugin {
  double rate = 48000.0;
  /// The host's nominal block length (bufsz:nominalBlockLength), frames; 0 if not given. The
  /// engine block is set to it, so that every run() of that length does one block's work
  /// instead of a whole larger block inside one callback now and then.
  int hostBlock = 0;
  std::string bundle;
  LV2_URID_Map* map = nullptr;
  LV2_Worker_Schedule* schedule = nullptr;
  LV2_Log_Logger logger{};
  Uris uris{};
  LV2_Atom_Forge forge{};
  const Variant* variant = &dpc::lv2::kVariants[0];
  void* ports[kPortCount] = {};
  float* extraOutputs[kMaxOutputs - 2] = {};  ///< outputs 3.. (ports kPortCount...)
  Scene* scene = nullptr;
  bool active = false;
  bool notifyScene = false;  ///< tell the host the scene path at the next run()
  Pose sent{};               ///< the pose last published to the engine
  bool sentValid = false;
  // The playing scene's path for save(), which LV2 may call concurrently with run(): a
  // seqlock (run() writes without waiting, save() retries until it reads a stable copy).
  // Empty for the bundle's default scene.
  std::atomic<uint32_t> pathSeq{0};
  char savedPath[kMaxPath] = {};

  /// Whoever swaps the scene (run() or restore()): records its path for save().
  void recordPath(const Scene& s) {
    pathSeq.fetch_add(1, std::memory_order_acq_rel);
    const size_t n = s.isDefault ? 0 : std::min(s.path.size(), kMaxPath - 1);
    std::memcpy(savedPath, s.path.data(), n);
    savedPath[n] = '\0';
    pathSeq.fetch_add(1, std::memory_order_release);
  }
  /// save(): a consistent copy of savedPath.
  std::string readPath() const {
    char copy[kMaxPath];
    for (;;) {
      const uint32_t before = pathSeq.load(std::memory_order_acquire);
      if (before & 1u) continue;
      std::memcpy(copy, savedPath, kMaxPath);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (pathSeq.load(std::memory_order_relaxed) == before) break;
    }
    copy[kMaxPath - 1] = '\0';
    return copy;
  }

  // Pose ports whose value left the declared range: each is logged once, off the audio
  // thread (by the worker, or at deactivate and cleanup without one). clamped: the ports
  // seen out of range (bit i for kPoseRanges[i]), with the first such value; reported: those
  // logged.
  std::atomic<uint32_t> clamped{0};
  std::atomic<float> firstOutside[kPosePorts] = {};
  uint32_t reported = 0;

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
  /// Audio thread, wait-free: records the ports out of range for the first time; true if any.
  bool noteClamped() {
    uint32_t fresh = 0;
    for (int i = 0; i < kPosePorts; ++i) {
      const float v = raw(i);
      const uint32_t bit = 1u << i;
      if (clampToPort(kPoseRanges[i], v) == v || (clamped.load(std::memory_order_relaxed) & bit))
        continue;
      firstOutside[i].store(v, std::memory_order_relaxed);
      fresh |= bit;
    }
    if (fresh) clamped.fetch_or(fresh, std::memory_order_release);
    return fresh != 0;
  }
};

/// Not the audio thread: logs each port clamped since the last call, once per instance.
void reportClamped(Plugin* p) {
  const uint32_t pending = p->clamped.load(std::memory_order_acquire) & ~p->reported;
  for (int i = 0; i < kPosePorts; ++i) {
    if (!(pending & (1u << i))) continue;
    const PortRange& r = kPoseRanges[i];
    const float v = p->firstOutside[i].load(std::memory_order_relaxed);
    const char* format =
        "dpc: port %s: %g is outside its range [%g, %g]; clamped to %g (logged "
        "once)\n";
    const double to = clampToPort(r, v);
    lv2_log_warning(&p->logger, format, r.symbol, double(v), double(r.min), double(r.max), to);
  }
  p->reported |= pending;
}

/// Any thread but the audio thread: the message of the last failed dpc call, logged after
/// `what` (the step that failed; nullptr when the message says it).
void logError(Plugin* p, const char* what) {
  const char* sep = what ? ": " : "";
  if (!what) what = "";
  lv2_log_error(&p->logger, "dpc: %s%s%s\n", what, sep, dpc_last_error());
}

/// Publishes a pose to an engine's selected listener and first source (wait-free; any thread).
/// The pose is within the ports' ranges (Plugin::pose), inside the scene's limits.
void publish(dpc_engine* e, const Pose& q) {
  dpc_engine_set_listener_pose(e, dpc_engine_selected_listener(e), q.v[0], q.v[1], q.v[2], q.v[3],
                               0.f);
  dpc_engine_set_source_position(e, 0, q.v[4], q.v[5], q.v[6]);
}

/// Whether the first propagation frame of a scene is computed before its first block:
/// - kOnWorker: on the calling thread, which is the LV2 worker's (a scene chosen by patch:Set);
/// - kNow: on the calling thread in a host without a worker (lv2apply and other offline hosts,
///   which run faster than real time and would otherwise render their first seconds dry);
/// - kOnPropagationThread: not here: the engine's propagation thread computes it once started,
///   and the plugin plays silence until that first impulse response arrives (a real-time host
///   with a worker: instantiate, activate and restore never wait for a frame).
enum class FirstFrame { kOnWorker, kNow, kOnPropagationThread };

/// The policy for a load outside the worker: a frame now only in a host without a worker.
FirstFrame firstFrameOutsideWorker(const Plugin* p) {
  return p->schedule ? FirstFrame::kOnPropagationThread : FirstFrame::kNow;
}

/// Control or worker thread: loads a scene at the host's rate with host inputs only, computes
/// its first frame for `pose` as `first` says and, if `start`, starts its propagation thread.
/// nullptr on failure (logged).
/// Control or worker thread: the engine for a scene file as this plugin plays it (the host's
/// rate and block, host inputs only, the variant's output format). A scene of more channels
/// than the plugin has outputs (an Ambisonic or loudspeaker scene in the stereo plugin) is
/// opened again as stereo, and the plugin says so. nullptr on failure (logged).
dpc_engine* createEngine(Plugin* p, const std::string& path) {
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.sample_rate = int(std::lround(p->rate));
  o.block_size = p->hostBlock;  // 0 keeps the scene's
  o.host_inputs_only = 1;
  o.output = p->variant->output;
  o.ambisonic_order = p->variant->ambisonicOrder;
  dpc_engine* e = nullptr;
  if (dpc_engine_create_from_file(path.c_str(), &o, &e) != DPC_OK) {
    logError(p, nullptr);  // the message names the scene file already
    return nullptr;
  }
  const int channels = dpc_engine_output_channels(e);
  if (channels <= p->variant->outputs) return e;
  dpc_engine_destroy(e);
  const char* format = "dpc: %s renders %d channels; %s plays it as stereo\n";
  lv2_log_note(&p->logger, format, path.c_str(), channels, p->variant->uri);
  o.output = DPC_OUTPUT_STEREO;
  if (dpc_engine_create_from_file(path.c_str(), &o, &e) == DPC_OK) return e;
  logError(p, nullptr);
  return nullptr;
}

Scene* loadScene(Plugin* p, const std::string& path, bool isDefault, const Pose& pose, bool start,
                 FirstFrame first) {
  dpc_engine* e = createEngine(p, path);
  if (!e) return nullptr;
  auto* s = new Scene;
  s->engine = e;
  s->path = path;
  s->isDefault = isDefault;
  s->channels = dpc_engine_output_channels(e);
  s->inputs.assign(size_t(dpc_engine_source_count(e)), nullptr);
  publish(e, pose);
  if (first != FirstFrame::kOnPropagationThread && dpc_engine_step(e) != DPC_OK)
    logError(p, "first propagation frame");
  if (start && dpc_engine_start(e) != DPC_OK) logError(p, "start");
  return s;
}

/// Instantiation thread: false (logged) for a host rate that is no number of Hz. A rate of 0
/// (or NaN, or beyond int) would become the options' 0, "keep the scene's rate", and the
/// plugin would play at a rate the host does not run; the C API checks the range itself.
bool usableRate(Plugin* p, double rate) {
  if (rate >= 1.0 && rate <= 1e9) return true;
  lv2_log_error(&p->logger, "dpc: the host's sample rate %g Hz is not a rate\n", rate);
  return false;
}

LV2_Handle instantiate(const LV2_Descriptor* descriptor, double rate, const char* bundlePath,
                       const LV2_Feature* const* features) {
  auto* p = new Plugin;
  p->variant = &dpc::lv2::variantOf(descriptor->URI);
  p->rate = rate;
  p->bundle = bundlePath;
  if (!p->bundle.empty() && p->bundle.back() != '/') p->bundle += '/';
  LV2_Log_Log* log = nullptr;
  for (int i = 0; features && features[i]; ++i) {
    if (!std::strcmp(features[i]->URI, LV2_URID__map))
      p->map = static_cast<LV2_URID_Map*>(features[i]->data);
    else if (!std::strcmp(features[i]->URI, LV2_WORKER__schedule))
      p->schedule = static_cast<LV2_Worker_Schedule*>(features[i]->data);
    else if (!std::strcmp(features[i]->URI, LV2_LOG__log))
      log = static_cast<LV2_Log_Log*>(features[i]->data);
  }
  p->hostBlock = dpc::lv2::nominalBlockLength(p->map, features);
  lv2_log_logger_init(&p->logger, p->map, log);
  if (!usableRate(p, rate)) {
    delete p;
    return nullptr;
  }
  if (p->map) {
    p->uris.map(p->map);
    lv2_atom_forge_init(&p->forge, p->map);
  }
  // No frame yet: activate() computes it (or has the propagation thread compute it) for the
  // pose the control ports hold then.
  p->scene = loadScene(p, p->bundle + kDefaultScene, true, p->pose(), false,
                       FirstFrame::kOnPropagationThread);
  if (!p->scene) {
    delete p;
    return nullptr;
  }
  return p;
}

void connectPort(LV2_Handle h, uint32_t port, void* data) {
  auto* p = static_cast<Plugin*>(h);
  if (port < kPortCount)
    p->ports[port] = data;
  else if (port - kPortCount < uint32_t(p->variant->outputs - 2))
    p->extraOutputs[port - kPortCount] = static_cast<float*>(data);
}

void activate(LV2_Handle h) {
  auto* p = static_cast<Plugin*>(h);
  // The control ports hold their values now: the first frame is computed for them (now in a
  // host without a worker, else by the propagation thread, which starts here).
  const Pose q = p->pose();
  publish(p->scene->engine, q);
  p->sent = q;
  p->sentValid = true;
  if (firstFrameOutsideWorker(p) == FirstFrame::kNow && dpc_engine_step(p->scene->engine) != DPC_OK)
    logError(p, "first propagation frame");
  if (dpc_engine_start(p->scene->engine) != DPC_OK) logError(p, "start");
  p->active = true;
}

void deactivate(LV2_Handle h) {
  auto* p = static_cast<Plugin*>(h);
  dpc_engine_stop(p->scene->engine);
  p->active = false;
  reportClamped(p);
}

/// Audio thread: writes patch:Set <scene> <path> to the notify port (if connected).
void writeScenePath(Plugin* p, LV2_Atom_Sequence* notify) {
  const uint32_t capacity = notify->atom.size;
  lv2_atom_forge_set_buffer(&p->forge, reinterpret_cast<uint8_t*>(notify), capacity);
  LV2_Atom_Forge_Frame seq;
  lv2_atom_forge_sequence_head(&p->forge, &seq, 0);
  lv2_atom_forge_frame_time(&p->forge, 0);
  LV2_Atom_Forge_Frame obj;
  lv2_atom_forge_object(&p->forge, &obj, 0, p->uris.patchSet);
  lv2_atom_forge_key(&p->forge, p->uris.patchProperty);
  lv2_atom_forge_urid(&p->forge, p->uris.sceneParam);
  lv2_atom_forge_key(&p->forge, p->uris.patchValue);
  lv2_atom_forge_path(&p->forge, p->scene->path.c_str(), uint32_t(p->scene->path.size()));
  lv2_atom_forge_pop(&p->forge, &obj);
  lv2_atom_forge_pop(&p->forge, &seq);
}

/// Audio thread: hands a scene path from a patch:Set to the worker (no allocation: the
/// message is built on the stack and copied by the host).
void requestScene(Plugin* p, const LV2_Atom* value) {
  if (!p->schedule || value->type != p->uris.atomPath || value->size == 0 ||
      value->size >= kMaxPath)
    return;
  alignas(WorkMessage) char buf[sizeof(WorkMessage) + kMaxPath];
  auto* m = reinterpret_cast<WorkMessage*>(buf);
  m->kind = WorkMessage::kLoad;
  m->scene = nullptr;
  m->pose = p->pose();
  m->start = p->active;
  std::memcpy(m->path, LV2_ATOM_BODY_CONST(value), value->size);
  m->path[value->size] = '\0';
  const uint32_t size = uint32_t(offsetof(WorkMessage, path) + value->size + 1);
  // A full worker queue drops the request; the host's next patch:Set tries again.
  p->schedule->schedule_work(p->schedule->handle, size, m);
}

void readControl(Plugin* p) {
  const auto* in = static_cast<const LV2_Atom_Sequence*>(p->ports[kControl]);
  if (!in || !p->map) return;
  LV2_ATOM_SEQUENCE_FOREACH(in, ev) {
    if (ev->body.type != p->uris.atomObject) continue;
    const auto* obj = reinterpret_cast<const LV2_Atom_Object*>(&ev->body);
    if (obj->body.otype == p->uris.patchGet) {
      p->notifyScene = true;
    } else if (obj->body.otype == p->uris.patchSet) {
      const LV2_Atom* property = nullptr;
      const LV2_Atom* value = nullptr;
      lv2_atom_object_get(obj, p->uris.patchProperty, &property, p->uris.patchValue, &value, 0);
      if (property && value && property->type == p->uris.atomUrid &&
          reinterpret_cast<const LV2_Atom_URID*>(property)->body == p->uris.sceneParam)
        requestScene(p, value);
    }
  }
}

/// Audio thread: the input through the scene's engine into the output ports, at most 8192
/// frames per engine call; a mono scene copied to the second output.
void process(Plugin* p, Scene* s, uint32_t frames) {
  auto* in = static_cast<const float*>(p->ports[kIn]);
  float* ports[kMaxOutputs] = {static_cast<float*>(p->ports[kOutL]),
                               static_cast<float*>(p->ports[kOutR])};
  std::copy(p->extraOutputs, p->extraOutputs + p->variant->outputs - 2, ports + 2);
  float* outs[kMaxOutputs];
  for (uint32_t done = 0; done < frames;) {
    const uint32_t n = std::min<uint32_t>(frames - done, 8192);
    for (auto& ptr : s->inputs) ptr = in + done;
    for (int c = 0; c < p->variant->outputs; ++c) outs[c] = ports[c] + done;
    dpc_engine_process(s->engine, s->inputs.data(), outs, int(n));
    if (s->channels == 1) std::copy(outs[0], outs[0] + n, outs[1]);
    done += n;
  }
}

void run(LV2_Handle h, uint32_t frames) {
  auto* p = static_cast<Plugin*>(h);
  readControl(p);
  auto* notify = static_cast<LV2_Atom_Sequence*>(p->ports[kNotify]);
  if (notify && p->map && p->notifyScene) {
    writeScenePath(p, notify);
    p->notifyScene = false;
  } else if (notify) {
    lv2_atom_sequence_clear(notify);  // an empty sequence (the host set atom.size to capacity)
    notify->atom.type = p->map ? p->uris.atomSequence : 0;
  }
  Scene* s = p->scene;
  if (p->noteClamped() && p->schedule) {
    const WorkMessage m{WorkMessage::kReportClamped, nullptr, {}, false, {}};
    p->schedule->schedule_work(p->schedule->handle, uint32_t(offsetof(WorkMessage, path)), &m);
  }
  const Pose q = p->pose();
  if (!p->sentValid || q != p->sent) {
    publish(s->engine, q);
    p->sent = q;
    p->sentValid = true;
  }
  if (p->ports[kLatency])
    *static_cast<float*>(p->ports[kLatency]) = float(dpc_engine_latency_frames(s->engine));
  process(p, s, frames);
}

/// Worker thread: loads a scene (and answers with it) or frees one.
LV2_Worker_Status work(LV2_Handle h, LV2_Worker_Respond_Function respond,
                       LV2_Worker_Respond_Handle handle, uint32_t size, const void* data) {
  auto* p = static_cast<Plugin*>(h);
  if (size < offsetof(WorkMessage, path)) return LV2_WORKER_ERR_UNKNOWN;
  const auto* m = static_cast<const WorkMessage*>(data);
  if (m->kind == WorkMessage::kFree) {
    delete m->scene;
    return LV2_WORKER_SUCCESS;
  }
  if (m->kind == WorkMessage::kReportClamped) {
    reportClamped(p);
    return LV2_WORKER_SUCCESS;
  }
  const std::string path(m->path, strnlen(m->path, size - offsetof(WorkMessage, path)));
  Scene* s = loadScene(p, path, false, m->pose, m->start, FirstFrame::kOnWorker);
  respond(handle, sizeof s, &s);  // nullptr on failure: the audio thread keeps the old scene
  return LV2_WORKER_SUCCESS;
}

/// Audio thread: swaps in the scene the worker loaded and sends the old one back to be freed.
LV2_Worker_Status workResponse(LV2_Handle h, uint32_t size, const void* data) {
  auto* p = static_cast<Plugin*>(h);
  if (size != sizeof(Scene*)) return LV2_WORKER_ERR_UNKNOWN;
  Scene* s = nullptr;
  std::memcpy(&s, data, sizeof s);
  if (!s) return LV2_WORKER_SUCCESS;
  WorkMessage m{};
  m.kind = WorkMessage::kFree;
  m.scene = p->scene;
  p->scene = s;
  p->recordPath(*s);
  p->sentValid = false;
  p->notifyScene = true;
  p->schedule->schedule_work(p->schedule->handle, uint32_t(offsetof(WorkMessage, path)), &m);
  return LV2_WORKER_SUCCESS;
}

/// Saves the chosen scene's path (nothing for the bundle's default scene). May run
/// concurrently with run(): reads the path through the seqlock, never the Scene.
LV2_State_Status save(LV2_Handle h, LV2_State_Store_Function store, LV2_State_Handle handle,
                      uint32_t, const LV2_Feature* const* features) {
  auto* p = static_cast<Plugin*>(h);
  std::string value = p->readPath();
  if (!p->map || value.empty()) return LV2_STATE_SUCCESS;
  LV2_State_Map_Path* mapPath = nullptr;
  for (int i = 0; features && features[i]; ++i)
    if (!std::strcmp(features[i]->URI, LV2_STATE__mapPath))
      mapPath = static_cast<LV2_State_Map_Path*>(features[i]->data);
  if (mapPath) {
    char* abstract = mapPath->abstract_path(mapPath->handle, value.c_str());
    value = abstract;
    std::free(abstract);
  }
  return store(handle, p->uris.sceneParam, value.c_str(), value.size() + 1, p->uris.atomPath,
               LV2_STATE_IS_POD | LV2_STATE_IS_PORTABLE);
}

/// Loads the saved scene (or the default one if the state holds none). Instantiation thread:
/// run() is not running meanwhile.
LV2_State_Status restore(LV2_Handle h, LV2_State_Retrieve_Function retrieve,
                         LV2_State_Handle handle, uint32_t, const LV2_Feature* const* features) {
  auto* p = static_cast<Plugin*>(h);
  if (!p->map) return LV2_STATE_ERR_NO_FEATURE;
  size_t size = 0;
  uint32_t type = 0, flags = 0;
  const void* value = retrieve(handle, p->uris.sceneParam, &size, &type, &flags);
  std::string path = p->bundle + kDefaultScene;
  bool isDefault = true;
  if (value) {
    if (type != p->uris.atomPath) return LV2_STATE_ERR_BAD_TYPE;
    path.assign(static_cast<const char*>(value), strnlen(static_cast<const char*>(value), size));
    isDefault = false;
    for (int i = 0; features && features[i]; ++i)
      if (!std::strcmp(features[i]->URI, LV2_STATE__mapPath)) {
        auto* mp = static_cast<LV2_State_Map_Path*>(features[i]->data);
        char* absolute = mp->absolute_path(mp->handle, path.c_str());
        path = absolute;
        std::free(absolute);
      }
  }
  if (path == p->scene->path) return LV2_STATE_SUCCESS;
  Scene* s = loadScene(p, path, isDefault, p->pose(), p->active, firstFrameOutsideWorker(p));
  if (!s) return LV2_STATE_ERR_UNKNOWN;
  delete p->scene;
  p->scene = s;
  p->recordPath(*s);
  p->sentValid = false;
  p->notifyScene = true;
  return LV2_STATE_SUCCESS;
}

void cleanup(LV2_Handle h) {
  auto* p = static_cast<Plugin*>(h);
  reportClamped(p);
  delete p->scene;
  delete p;
}

const void* extensionData(const char* uri) {
  static const LV2_Worker_Interface worker = {work, workResponse, nullptr};
  static const LV2_State_Interface state = {save, restore};
  if (!std::strcmp(uri, LV2_WORKER__interface)) return &worker;
  if (!std::strcmp(uri, LV2_STATE__interface)) return &state;
  return nullptr;
}

template <size_t... I>
constexpr std::array<LV2_Descriptor, sizeof...(I)> descriptors(std::index_sequence<I...>) {
  return {LV2_Descriptor{dpc::lv2::kVariants[I].uri, instantiate, connectPort, activate, run, deactivate,
                         cleanup, extensionData}...};
}
constexpr auto kDescriptors = descriptors(std::make_index_sequence<std::size(dpc::lv2::kVariants)>());

}  // namespace

extern "C" LV2_SYMBOL_EXPORT const LV2_Descriptor* lv2_descriptor(uint32_t index) {
  return index < kDescriptors.size() ? &kDescriptors[index] : nullptr;
}
