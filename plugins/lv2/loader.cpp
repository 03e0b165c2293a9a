#include "plugins/lv2/loader.h"

#include <cmath>
#include <exception>
#include <utility>

namespace dpc::lv2 {

namespace {

/// Control or loader thread: the engine for a scene file as this plugin plays it (the host's
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

/// Loader thread: the scene at `path`, built; nullptr on failure (logged).
Scene* buildScene(Plugin* p, const std::string& path, bool isDefault) {
  dpc_engine* e = createEngine(p, path);
  if (!e) return nullptr;
  auto* s = new Scene;
  s->engine = e;
  s->path = path;
  s->isDefault = isDefault;
  s->channels = dpc_engine_output_channels(e);
  s->inputs.assign(size_t(dpc_engine_source_count(e)), nullptr);
  return s;
}

/// Loader thread: builds the scene; in a host with a worker computes its first frame for the
/// pose run() last saw and starts it if the plugin is active; hands it to run() unless a newer
/// load was requested meanwhile.
void loadJob(Plugin* p, const std::string& path, bool isDefault, uint64_t generation) {
  Scene* s = buildScene(p, path, isDefault);
  if (!s) {
    const char* format = "dpc: %s is not loaded; the plugin keeps the scene it plays (silence "
                         "if none)\n";
    lv2_log_error(&p->logger, format, path.c_str());
    return;
  }
  if (p->schedule) {
    publish(s->engine, p->latest());
    if (dpc_engine_step(s->engine) != DPC_OK) logError(p, "first propagation frame");
  }
  if (generation != p->loadGeneration.load(std::memory_order_acquire)) {
    delete s;  // superseded by a newer request
    return;
  }
  Scene* stale = nullptr;
  {
    std::lock_guard lock(p->lifecycle);
    if (p->schedule && p->active && dpc_engine_start(s->engine) != DPC_OK) logError(p, "start");
    stale = p->incoming.exchange(s, std::memory_order_acq_rel);
  }
  delete stale;  // loaded earlier, never swapped in
  const char* format = "dpc: %s is loaded (%d sources, %d output channels); it plays from the "
                       "next block\n";
  lv2_log_note(&p->logger, format, path.c_str(), dpc_engine_source_count(s->engine),
               s->channels);
}

}  // namespace

void startLoad(Plugin* p, const std::string& path, bool isDefault) {
  std::lock_guard lock(p->loaderMutex);
  const uint64_t generation = p->loadGeneration.fetch_add(1, std::memory_order_acq_rel) + 1;
  if (p->loader.joinable()) p->loader.join();
  collectOutgoing(p);
  try {
    p->requestedPath = path;
    p->loader = std::thread([p, path, isDefault, generation] {
      try {
        loadJob(p, path, isDefault, generation);
      } catch (const std::exception& e) {
        lv2_log_error(&p->logger, "dpc: %s is not loaded: %s\n", path.c_str(), e.what());
      }
    });
  } catch (const std::exception& e) {
    lv2_log_error(&p->logger, "dpc: %s is not loaded: no thread to load it (%s)\n", path.c_str(),
                  e.what());
  }
}

void waitForLoad(Plugin* p) {
  std::lock_guard lock(p->loaderMutex);
  if (p->loader.joinable()) p->loader.join();
}

void firstFrame(Plugin* p, Scene& s) {
  publish(s.engine, p->pose());
  try {
    // On a thread of the plugin's own, as every propagation frame (loader.h).
    std::thread([p, &s] {
      if (dpc_engine_step(s.engine) != DPC_OK) logError(p, "first propagation frame");
    }).join();
  } catch (const std::exception& e) {
    lv2_log_error(&p->logger, "dpc: first propagation frame: no thread (%s)\n", e.what());
  }
}

bool adoptNow(Plugin* p) {
  waitForLoad(p);
  Scene* s = p->incoming.exchange(nullptr, std::memory_order_acq_rel);
  if (!s) return false;
  firstFrame(p, *s);
  {
    std::lock_guard lock(p->lifecycle);
    if (p->active && dpc_engine_start(s->engine) != DPC_OK) logError(p, "start");
  }
  delete std::exchange(p->scene, s);
  p->recordPath(*s);
  p->sentValid = false;
  p->notifyScene = true;
  return true;
}

void collectOutgoing(Plugin* p) {
  delete p->outgoing.exchange(nullptr, std::memory_order_acq_rel);
}

}  // namespace dpc::lv2
