// LV2 plugin "dpc room": a mono dry input rendered through a dpc scene to a stereo (or
// binaural, if the scene says so) output. A thin layer over the public C API (include/dpc/dpc.h):
// one dpc_engine per loaded scene, built in the background on a thread of the plugin's own
// (loader.h), whose propagation thread runs inside the instance; run() only publishes the
// control ports' poses (wait-free), swaps in a newly loaded scene and calls dpc_engine_process
// (no allocation, locks or waiting). Another scene is chosen through the patch:Parameter
// <URI#scene> (atom:Path) and saved with the plugin's state (docs/design.md "LV2 plugin").
#include <lv2/atom/atom.h>
#include <lv2/atom/forge.h>
#include <lv2/atom/util.h>
#include <lv2/core/lv2.h>
#include <lv2/log/log.h>
#include <lv2/log/logger.h>
#include <lv2/patch/patch.h>
#include <lv2/state/state.h>
#include <lv2/urid/urid.h>
#include <lv2/worker/worker.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <utility>

#include "dpc/dpc.h"
#include "plugins/lv2/host.h"
#include "plugins/lv2/loader.h"
#include "plugins/lv2/plugin.h"

namespace {

using namespace dpc::lv2;

/// Worker messages: load a scene (path follows), free the scene run() replaced, or log the
/// ports clamped so far.
struct WorkMessage {
  enum Kind : uint32_t { kLoad, kCollect, kReportClamped } kind;
  char path[1];  ///< kLoad: NUL-terminated, the message's tail
};
constexpr uint32_t kHeaderSize = uint32_t(offsetof(WorkMessage, path));

/// Instantiation thread: false (logged) for a host rate that is no number of Hz. A rate of 0
/// (or NaN, or beyond int) would become the options' 0, "keep the scene's rate", and the
/// plugin would play at a rate the host does not run. The C API checks the range itself when
/// the scene loads (a rate outside it fails the load).
bool usableRate(Plugin* p, double rate) {
  if (rate >= 1.0 && rate <= 1e9) return true;
  lv2_log_error(&p->logger, "dpc: the host's sample rate %g Hz is not a rate\n", rate);
  return false;
}

LV2_Handle instantiate(const LV2_Descriptor* descriptor, double rate, const char* bundlePath,
                       const LV2_Feature* const* features) {
  auto* p = new (std::nothrow) Plugin;
  if (!p) return nullptr;
  p->variant = &variantOf(descriptor->URI);
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
  p->hostBlock = nominalBlockLength(p->map, features);
  lv2_log_logger_init(&p->logger, p->map, log);
  if (!usableRate(p, rate)) {
    delete p;
    return nullptr;
  }
  if (p->map) {
    p->uris.map(p->map);
    lv2_atom_forge_init(&p->forge, p->map);
  }
  // In the background (loader.h): instantiate returns at once, whatever the scene's size. A
  // host without a worker (an offline host) waits here instead and learns of a scene that
  // does not load from a NULL instance.
  startLoad(p, p->bundle + kDefaultScene, true);
  if (!p->schedule) {
    waitForLoad(p);
    if (!p->incoming.load(std::memory_order_acquire)) {
      delete p;
      return nullptr;
    }
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

/// Wait-free; activate() or run(): the pose the ports hold, for a scene that loads meanwhile.
void storeLatest(Plugin* p, const Pose& q) {
  for (int i = 0; i < kPosePorts; ++i) p->latestPose[i].store(q.v[i], std::memory_order_relaxed);
}

void activate(LV2_Handle h) {
  auto* p = static_cast<Plugin*>(h);
  const Pose q = p->pose();
  storeLatest(p, q);
  // A host without a worker gets the scene and its first frame for the ports' pose now, so
  // that sound comes out of its first blocks; with a worker, the plugin plays silence until
  // the loader hands the scene over.
  if (!p->schedule && !adoptNow(p) && p->scene) firstFrame(p, *p->scene);
  std::lock_guard lock(p->lifecycle);
  p->active = true;
  for (Scene* s : {p->scene, p->incoming.load(std::memory_order_acquire)}) {
    if (!s) continue;
    publish(s->engine, q);
    if (dpc_engine_start(s->engine) != DPC_OK) logError(p, "start");
  }
  p->sent = q;
  p->sentValid = p->scene != nullptr;
}

void deactivate(LV2_Handle h) {
  auto* p = static_cast<Plugin*>(h);
  {
    std::lock_guard lock(p->lifecycle);
    p->active = false;
    for (Scene* s : {p->scene, p->incoming.load(std::memory_order_acquire)})
      if (s) dpc_engine_stop(s->engine);
  }
  collectOutgoing(p);
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
  const std::string& path = p->scene->path;
  lv2_atom_forge_path(&p->forge, path.c_str(), uint32_t(path.size()));
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
  std::memcpy(m->path, LV2_ATOM_BODY_CONST(value), value->size);
  m->path[value->size] = '\0';
  const uint32_t size = kHeaderSize + value->size + 1;
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

/// Audio thread: the connected outputs, `n` frames each (at most 8192) from `done`.
int outputs(Plugin* p, uint32_t done, float** outs) {
  float* ports[kMaxOutputs] = {static_cast<float*>(p->ports[kOutL]),
                               static_cast<float*>(p->ports[kOutR])};
  std::copy(p->extraOutputs, p->extraOutputs + p->variant->outputs - 2, ports + 2);
  for (int c = 0; c < p->variant->outputs; ++c) outs[c] = ports[c] ? ports[c] + done : nullptr;
  return p->variant->outputs;
}

/// Audio thread: the input through the scene's engine into the output ports, at most 8192
/// frames per engine call; a mono scene copied to the second output; silence without a scene.
void process(Plugin* p, Scene* s, uint32_t frames) {
  auto* in = static_cast<const float*>(p->ports[kIn]);
  float* outs[kMaxOutputs];
  for (uint32_t done = 0; done < frames;) {
    const uint32_t n = std::min<uint32_t>(frames - done, 8192);
    const int channels = outputs(p, done, outs);
    if (!s) {
      for (int c = 0; c < channels; ++c)
        if (outs[c]) std::fill(outs[c], outs[c] + n, 0.f);
    } else {
      for (auto& ptr : s->inputs) ptr = in + done;
      dpc_engine_process(s->engine, s->inputs.data(), outs, int(n));
      if (s->channels == 1) std::copy(outs[0], outs[0] + n, outs[1]);
    }
    done += n;
  }
}

/// Audio thread: asks the worker to free the scene run() replaced (once per scene).
void scheduleCollect(Plugin* p) {
  if (p->collectScheduled || !p->schedule) return;
  const WorkMessage m{WorkMessage::kCollect, {}};
  p->collectScheduled =
      p->schedule->schedule_work(p->schedule->handle, kHeaderSize, &m) == LV2_WORKER_SUCCESS;
}

/// Audio thread, wait-free: swaps in the scene the loader handed over, if any, once the scene
/// it replaced last time has been freed; the host hears of it on the notify port.
void swapInLoaded(Plugin* p) {
  if (p->outgoing.load(std::memory_order_acquire)) {
    scheduleCollect(p);  // again, if the worker's queue was full
    return;
  }
  p->collectScheduled = false;
  Scene* s = p->incoming.exchange(nullptr, std::memory_order_acq_rel);
  if (!s) return;
  Scene* old = std::exchange(p->scene, s);
  p->recordPath(*s);
  p->sentValid = false;
  p->notifyScene = true;
  if (!old) return;
  p->outgoing.store(old, std::memory_order_release);
  scheduleCollect(p);
}

void run(LV2_Handle h, uint32_t frames) {
  auto* p = static_cast<Plugin*>(h);
  readControl(p);
  swapInLoaded(p);
  Scene* s = p->scene;
  auto* notify = static_cast<LV2_Atom_Sequence*>(p->ports[kNotify]);
  if (notify && p->map && p->notifyScene && s) {
    writeScenePath(p, notify);
    p->notifyScene = false;
  } else if (notify) {
    lv2_atom_sequence_clear(notify);  // an empty sequence (the host set atom.size to capacity)
    notify->atom.type = p->map ? p->uris.atomSequence : 0;
  }
  if (p->noteClamped() && p->schedule) {
    const WorkMessage m{WorkMessage::kReportClamped, {}};
    p->schedule->schedule_work(p->schedule->handle, kHeaderSize, &m);
  }
  const Pose q = p->pose();
  if (s && (!p->sentValid || q != p->sent)) {
    publish(s->engine, q);
    p->sent = q;
    p->sentValid = true;
  }
  storeLatest(p, q);
  if (p->ports[kLatency])
    *static_cast<float*>(p->ports[kLatency]) = s ? float(dpc_engine_latency_frames(s->engine)) : 0.f;
  process(p, s, frames);
}

/// Worker thread: starts loading a scene (loader.h), frees the scene run() replaced, or logs
/// the ports clamped.
LV2_Worker_Status work(LV2_Handle h, LV2_Worker_Respond_Function, LV2_Worker_Respond_Handle,
                       uint32_t size, const void* data) {
  auto* p = static_cast<Plugin*>(h);
  if (size < kHeaderSize) return LV2_WORKER_ERR_UNKNOWN;
  const auto* m = static_cast<const WorkMessage*>(data);
  if (m->kind == WorkMessage::kCollect) {
    collectOutgoing(p);
  } else if (m->kind == WorkMessage::kReportClamped) {
    reportClamped(p);
  } else {
    startLoad(p, std::string(m->path, strnlen(m->path, size - kHeaderSize)), false);
  }
  return LV2_WORKER_SUCCESS;
}

/// Audio thread: nothing to do; loaded scenes are swapped in by run() (swapInLoaded).
LV2_Worker_Status workResponse(LV2_Handle, uint32_t, const void*) {
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

/// Loads the saved scene (or the default one if the state holds none) unless it is the one
/// already requested: in the background in a host with a worker (run() swaps it in when it is
/// ready), now in a host without one. Instantiation thread: run() is not running meanwhile.
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
  {
    std::lock_guard lock(p->loaderMutex);
    if (path == p->requestedPath) return LV2_STATE_SUCCESS;
  }
  startLoad(p, path, isDefault);
  if (p->schedule) return LV2_STATE_SUCCESS;
  return adoptNow(p) ? LV2_STATE_SUCCESS : LV2_STATE_ERR_UNKNOWN;
}

/// Waits for a load in progress, then frees every scene: nothing of the plugin (nor of dpc's
/// threads, api/scheduler_lease.h) runs after cleanup returns.
void cleanup(LV2_Handle h) {
  auto* p = static_cast<Plugin*>(h);
  waitForLoad(p);
  reportClamped(p);
  collectOutgoing(p);
  delete p->incoming.exchange(nullptr, std::memory_order_acq_rel);
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
  return {LV2_Descriptor{kVariants[I].uri, instantiate, connectPort, activate, run, deactivate,
                         cleanup, extensionData}...};
}
constexpr auto kDescriptors = descriptors(std::make_index_sequence<std::size(kVariants)>());

}  // namespace

extern "C" LV2_SYMBOL_EXPORT const LV2_Descriptor* lv2_descriptor(uint32_t index) {
  return index < kDescriptors.size() ? &kDescriptors[index] : nullptr;
}
