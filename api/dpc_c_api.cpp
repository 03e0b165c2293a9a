// The C API (include/dpc/dpc.h) over LiveSession: the engine handle owns the scene, the dry
// signals and the session; every entry point catches exceptions and stores their text in a
// thread-local message (docs/design.md "Library boundary").
#include <cmath>
#include <exception>
#include <memory>
#include <new>
#include <string>

#include "dpc/dpc.h"
#include "engine/input_error.h"
#include "engine/scene.h"
#include "runtime/live_session.h"
#include "runtime/render_pipeline.h"

struct dpc_engine {
  dpc::SceneDesc scene;
  dpc::DrySignals dry;
  std::unique_ptr<dpc::LiveSession> session;
  int sources = 0;
};

namespace {

thread_local std::string lastError;

dpc_status fail(dpc_status status, const char* message) {
  try {
    lastError = message;
  } catch (...) {
  }
  return status;
}

// Runs f, turning exceptions into status codes and the thread's last-error text.
template <class F>
dpc_status guarded(F&& f) {
  try {
    return f();
  } catch (const dpc::InputError& e) {
    return fail(DPC_ERR_INPUT, e.what());
  } catch (const std::bad_alloc&) {
    return fail(DPC_ERR_INTERNAL, "out of memory");
  } catch (const std::exception& e) {
    return fail(DPC_ERR_INTERNAL, e.what());
  } catch (...) {
    return fail(DPC_ERR_INTERNAL, "unknown error");
  }
}

constexpr float kDegrees = 3.14159265358979323846f / 180.f;

}  // namespace

extern "C" {

const char* dpc_last_error(void) {
  return lastError.c_str();
}

const char* dpc_version(void) {
  return DPC_VERSION_STRING;
}

dpc_status dpc_engine_create_from_file(const char* scene_path, dpc_engine** out) {
  if (!out) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_file: out is NULL");
  *out = nullptr;
  if (!scene_path)
    return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_file: scene_path is NULL");
  return guarded([&] {
    auto engine = std::make_unique<dpc_engine>();
    engine->scene = dpc::loadScene(scene_path);
    engine->dry = dpc::loadDrySignals(engine->scene);
    engine->sources = int(engine->scene.sources.size());
    dpc::LiveSession::Options options;
    options.deviceChannels = dpc::outputChannels(engine->scene.audio.output);
    engine->session = std::make_unique<dpc::LiveSession>(engine->scene, engine->scene.propagation,
                                                         engine->dry, options);
    *out = engine.release();
    return DPC_OK;
  });
}

void dpc_engine_destroy(dpc_engine* engine) {
  if (!engine) return;
  try {
    engine->session->stop();
  } catch (...) {
  }
  delete engine;
}

dpc_status dpc_engine_start(dpc_engine* engine) {
  if (!engine) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_start: engine is NULL");
  return guarded([&] {
    engine->session->start();
    return DPC_OK;
  });
}

dpc_status dpc_engine_stop(dpc_engine* engine) {
  if (!engine) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_stop: engine is NULL");
  return guarded([&] {
    engine->session->stop();
    return DPC_OK;
  });
}

dpc_status dpc_engine_set_listener(dpc_engine* engine, float x, float y, float z, float yaw_degrees,
                                   float pitch_degrees) {
  if (!engine) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_set_listener: engine is NULL");
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || !std::isfinite(yaw_degrees) ||
      !std::isfinite(pitch_degrees))
    return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_set_listener: non-finite pose");
  engine->session->setPose(glm::vec3(x, y, z), yaw_degrees * kDegrees, 0.0,
                           pitch_degrees * kDegrees);
  return DPC_OK;
}

dpc_status dpc_engine_set_source_position(dpc_engine* engine, int source, float x, float y,
                                          float z) {
  // Any thread: no message on failure (setting it would allocate).
  if (!engine || source < 0 || source >= engine->sources || !std::isfinite(x) ||
      !std::isfinite(y) || !std::isfinite(z))
    return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->setSourcePosition(size_t(source), glm::vec3(x, y, z))
             ? DPC_OK
             : DPC_ERR_INVALID_ARGUMENT;
}

dpc_status dpc_engine_set_object_pose(dpc_engine* engine, int object, float x, float y, float z,
                                      float qx, float qy, float qz, float qw) {
  if (!engine || object < 0 || object >= int(engine->scene.objects.size())) return DPC_ERR_INVALID_ARGUMENT;
  const float q[4] = {qx, qy, qz, qw};
  for (float v : {x, y, z, qx, qy, qz, qw})
    if (!std::isfinite(v)) return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->setObjectPose(size_t(object), glm::vec3(x, y, z), q)
             ? DPC_OK
             : DPC_ERR_INVALID_ARGUMENT;
}

dpc_status dpc_engine_process(dpc_engine* engine, const float* const* inputs, float* const* outputs,
                              int frames) {
  if (!engine || !outputs) return DPC_ERR_INVALID_ARGUMENT;
  // The session adapts any callback size to its block; sizes outside 1..8192 output nothing and
  // are counted (dpc_stats.rejected_callbacks).
  engine->session->render(inputs, outputs, frames);
  return frames >= 1 && frames <= dpc::LiveSession::kMaxCallbackFrames ? DPC_OK
                                                                         : DPC_ERR_INVALID_ARGUMENT;
}

int dpc_engine_sample_rate(const dpc_engine* e) {
  return e ? e->session->sampleRate() : 0;
}
int dpc_engine_block_size(const dpc_engine* e) {
  return e ? e->session->blockSize() : 0;
}
int dpc_engine_output_channels(const dpc_engine* e) {
  return e ? e->session->irChannels() : 0;
}
int dpc_engine_source_count(const dpc_engine* e) {
  return e ? e->sources : 0;
}
int dpc_engine_object_count(const dpc_engine* e) {
  return e ? int(e->scene.objects.size()) : 0;
}
int dpc_engine_latency_frames(const dpc_engine* e) {
  return e ? e->session->adapterLatencyFrames() : 0;
}

dpc_status dpc_engine_get_stats(dpc_engine* engine, dpc_stats* out) {
  if (!engine || !out) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_get_stats: NULL");
  return guarded([&] {
    const auto s = engine->session->status();
    out->frames = s.frames;
    out->frame_ms = s.frameMs;
    out->rays_per_second = s.raysPerSecond;
    out->cache_entries = s.cacheEntries;
    out->irs_applied = s.irsApplied;
    out->irs_dropped = s.irsDropped;
    out->ir_age_ms = s.irAgeMs;
    out->blocks = s.blocks;
    out->nan_blocks = s.nanBlocks;
    out->late_callbacks = s.lateCallbacks;
    out->rejected_callbacks = s.rejectedCallbacks;
    out->cache_bytes = s.cacheBytes;
    out->cache_budget_bytes = s.cacheBudgetBytes;
    out->cache_merged_entries = s.cacheMergedEntries;
    out->cache_merged_energy_fraction = s.cacheMergedEnergyFraction;
    return DPC_OK;
  });
}

}  // extern "C"
