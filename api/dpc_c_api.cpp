// The C API (include/dpc/dpc.h) over LiveSession: the engine handle owns the scene, the dry
// signals and the session; every entry point catches exceptions and stores their text in a
// thread-local message (docs/design.md "Library boundary").
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <glm/geometric.hpp>
#include <memory>
#include <new>
#include <string>

#include "dpc/dpc.h"
#include "audio/rt_check.h"
#include "common/air_absorption.h"
#include "common/input_error.h"
#include "scene/scene.h"
#include "runtime/live_session.h"
#include "runtime/render_pipeline.h"

struct dpc_engine {
  dpc::SceneDesc scene;  ///< built by create, then moved into the session, which shares it
  dpc::DrySignals dry;   ///< likewise
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

// Applies dpc_engine_options to a loaded scene; returns a message for a bad option.
const char* applyOptions(const dpc_engine_options* o, dpc::SceneDesc& scene) {
  if (!o) return nullptr;
  if (o->sample_rate != 0) {
    if (o->sample_rate < 8000 || o->sample_rate > 384000)
      return "dpc_engine_options.sample_rate: outside 8000..384000 Hz";
    scene.audio.sampleRate = o->sample_rate;
  }
  if (o->block_size != 0) {
    if (o->block_size < 16 || o->block_size > 8192)
      return "dpc_engine_options.block_size: outside 16..8192 frames";
    scene.audio.blockSize = o->block_size;
  }
  if (o->rays_per_frame != 0) {
    if (o->rays_per_frame < 0) return "dpc_engine_options.rays_per_frame: must be > 0";
    scene.propagation.raysPerFrame = o->rays_per_frame;
  }
  switch (o->output) {
    case DPC_OUTPUT_SCENE:
      break;
    case DPC_OUTPUT_MONO:
      scene.audio.output = dpc::OutputFormat::kMono;
      break;
    case DPC_OUTPUT_STEREO:
      scene.audio.output = dpc::OutputFormat::kStereo;
      break;
    case DPC_OUTPUT_BINAURAL:
      scene.audio.output = dpc::OutputFormat::kBinaural;
      break;
    default:
      return "dpc_engine_options.output: not a dpc_output_format";
  }
  return nullptr;
}

// One-line error for scene data, in the loader's "FILE: FIELD: problem" form.
[[noreturn]] void bad(const std::string& field, const std::string& problem) {
  throw dpc::InputError("dpc_scene_data", field, problem);
}

void checkFinite(float v, const std::string& field) {
  if (!std::isfinite(v)) bad(field, "not a finite number");
}

void checkRange(double v, double lo, double hi, const std::string& field, const char* unit) {
  if (!(v >= lo && v <= hi))
    bad(field, std::to_string(v) + " is outside [" + std::to_string(lo) + ", " +
                   std::to_string(hi) + "]" + unit);
}

// The SceneDesc a scene file with the same content would give (docs/scene-format.md), checked
// with the same bounds.
dpc::SceneDesc sceneFromData(const dpc_scene_data& d) {
  dpc::SceneDesc scene;
  scene.path = "dpc_scene_data";
  if (d.material_count < 1 || !d.materials) bad("materials", "at least one material is required");
  for (int i = 0; i < d.material_count; ++i) {
    const dpc_material& m = d.materials[i];
    const std::string f = "materials[" + std::to_string(i) + "]";
    dpc::Material mat;
    mat.name = m.name ? m.name : "material " + std::to_string(i);
    for (int b = 0; b < DPC_BANDS; ++b) {
      checkRange(m.absorption[b], 0.0, 1.0, f + ".absorption[" + std::to_string(b) + "]", "");
      mat.absorption[b] = m.absorption[b];
    }
    checkRange(m.scattering, 0.0, 1.0, f + ".scattering", "");
    mat.scattering = dpc::Bands(m.scattering);
    scene.materials.push_back(mat);
  }
  const dpc_mesh& mesh = d.mesh;
  if (mesh.triangle_count == 0 || !mesh.vertices || !mesh.indices || !mesh.materials)
    bad("mesh", "vertices, indices and materials are required, with triangle_count > 0");
  for (uint32_t v = 0; v < mesh.vertex_count; ++v) {
    const float* p = mesh.vertices + size_t(v) * 3;
    for (int k = 0; k < 3; ++k)
      checkFinite(p[k], "mesh.vertices[" + std::to_string(size_t(v) * 3 + size_t(k)) + "]");
    scene.mesh.vertices.emplace_back(p[0], p[1], p[2]);
  }
  for (uint32_t t = 0; t < mesh.triangle_count; ++t) {
    std::array<uint32_t, 3> tri;
    for (int k = 0; k < 3; ++k) {
      tri[size_t(k)] = mesh.indices[size_t(t) * 3 + size_t(k)];
      if (tri[size_t(k)] >= mesh.vertex_count)
        bad("mesh.indices[" + std::to_string(size_t(t) * 3 + size_t(k)) + "]",
            std::to_string(tri[size_t(k)]) + " >= vertex_count " +
                std::to_string(mesh.vertex_count));
    }
    const glm::vec3 a = scene.mesh.vertices[tri[0]], b = scene.mesh.vertices[tri[1]],
                    c = scene.mesh.vertices[tri[2]];
    if (!(glm::length(glm::cross(b - a, c - a)) > 0.f))
      bad("mesh.indices", "triangle " + std::to_string(t) + " has zero area");
    if (mesh.materials[t] >= uint32_t(d.material_count))
      bad("mesh.materials[" + std::to_string(t) + "]", std::to_string(mesh.materials[t]) +
                                                           " >= material_count " +
                                                           std::to_string(d.material_count));
    scene.mesh.triangles.push_back(tri);
    scene.mesh.materialIndex.push_back(mesh.materials[t]);
  }
  if (d.source_count < 1 || !d.sources) bad("sources", "at least one source is required");
  for (int i = 0; i < d.source_count; ++i) {
    const dpc_source& s = d.sources[i];
    const std::string f = "sources[" + std::to_string(i) + "]";
    dpc::SourceDesc src;
    src.name = "source " + std::to_string(i);
    for (int k = 0; k < 3; ++k) checkFinite(s.position[k], f + ".position");
    src.position = glm::vec3(s.position[0], s.position[1], s.position[2]);
    checkRange(s.gain_db, -200.0, 200.0, f + ".gain_db", " dB");
    src.gainDb = s.gain_db;
    src.loop = s.loop != 0;
    if (!s.signal && s.signal_frames > 0) bad(f + ".signal", "NULL with signal_frames > 0");
    for (size_t n = 0; n < s.signal_frames; ++n)
      if (!std::isfinite(s.signal[n]))
        bad(f + ".signal", "sample " + std::to_string(n) + " is not finite");
    scene.sources.push_back(src);
  }
  dpc::ListenerDesc l;
  for (int k = 0; k < 3; ++k) checkFinite(d.listener_position[k], "listener_position");
  l.position = glm::vec3(d.listener_position[0], d.listener_position[1], d.listener_position[2]);
  if (!(d.listener_radius > 0.f) || !std::isfinite(d.listener_radius))
    bad("listener_radius", "must be a finite number > 0 m");
  l.radius = d.listener_radius;
  checkFinite(d.listener_yaw_degrees, "listener_yaw_degrees");
  checkFinite(d.listener_pitch_degrees, "listener_pitch_degrees");
  l.yawDegrees = d.listener_yaw_degrees;
  l.pitchDegrees = d.listener_pitch_degrees;
  l.name = "listener 0";
  scene.listeners.push_back(l);
  if (d.additional_listener_count < 0 || d.additional_listener_count > 63)
    bad("additional_listener_count", "must be in 0..63");
  if (d.additional_listener_count > 0 && !d.additional_listeners)
    bad("additional_listeners", "NULL with additional_listener_count > 0");
  for (int i = 0; i < d.additional_listener_count; ++i) {
    const dpc_listener& a = d.additional_listeners[i];
    const std::string f = "additional_listeners[" + std::to_string(i) + "]";
    dpc::ListenerDesc extra;
    extra.name = "listener " + std::to_string(i + 1);
    for (int k = 0; k < 3; ++k) checkFinite(a.position[k], f + ".position");
    extra.position = glm::vec3(a.position[0], a.position[1], a.position[2]);
    if (!(a.radius > 0.f) || !std::isfinite(a.radius))
      bad(f + ".radius", "must be a finite number > 0 m");
    extra.radius = a.radius;
    checkFinite(a.yaw_degrees, f + ".yaw_degrees");
    checkFinite(a.pitch_degrees, f + ".pitch_degrees");
    extra.yawDegrees = a.yaw_degrees;
    extra.pitchDegrees = a.pitch_degrees;
    scene.listeners.push_back(extra);
  }
  // Bounds of the scene file's "propagation" and "audio" (scene/scene.cpp).
  dpc::PropagationSettings& p = scene.propagation;
  checkRange(d.rays_per_frame, 1, 100'000'000, "rays_per_frame", "");
  checkRange(d.max_order, 0, 10'000, "max_order", "");
  if (!(d.patch_size > 0.f) || !std::isfinite(d.patch_size)) bad("patch_size", "must be > 0 m");
  checkRange(d.cache_tau, 0.0, 1e6, "cache_tau", " s");
  checkRange(d.frame_rate, 1.0, 120.0, "frame_rate", " Hz");
  if (!(d.ir_length > 0.f && d.ir_length <= 60.f)) bad("ir_length", "outside (0, 60] s");
  checkRange(d.temperature, -50.0, 60.0, "temperature", " degrees C");
  checkRange(d.humidity, 0.0, 100.0, "humidity", " %");
  p.raysPerFrame = d.rays_per_frame;
  p.maxOrder = d.max_order;
  p.patchSize = d.patch_size;
  p.cacheTau = d.cache_tau;
  p.frameRate = d.frame_rate;
  p.irLength = d.ir_length;
  p.seed = d.seed;
  p.temperatureC = d.temperature;
  p.humidityPercent = d.humidity;
  if (d.speed_of_sound == 0.f) {
    p.speedOfSound = float(dpc::speedOfSoundAt(p.temperatureC));
  } else {
    checkRange(d.speed_of_sound, 1.0, 10000.0, "speed_of_sound", " m/s");
    p.speedOfSound = d.speed_of_sound;
  }
  p.airAbsorption = d.air_absorption != 0;
  p.diffraction = d.diffraction != 0;
  checkRange(d.sample_rate, 8000, 384000, "sample_rate", " Hz");
  checkRange(d.block_size, 16, 8192, "block_size", " frames");
  scene.audio.sampleRate = d.sample_rate;
  scene.audio.blockSize = d.block_size;
  switch (d.output) {
    case DPC_OUTPUT_MONO:
      scene.audio.output = dpc::OutputFormat::kMono;
      break;
    case DPC_OUTPUT_STEREO:
      scene.audio.output = dpc::OutputFormat::kStereo;
      break;
    case DPC_OUTPUT_BINAURAL:
      scene.audio.output = dpc::OutputFormat::kBinaural;
      break;
    default:
      bad("output", "must be DPC_OUTPUT_MONO, _STEREO or _BINAURAL");
  }
  return scene;
}

// Builds the session over a complete scene and dry signals.
dpc_engine* finish(std::unique_ptr<dpc_engine> engine) {
  engine->sources = int(engine->scene.sources.size());
  dpc::LiveSession::Options options;
  options.deviceChannels = dpc::outputChannels(engine->scene.audio.output);
  // The session shares the scene and the signals; until the host sets a pose, every listener
  // stands where the scene puts it at time 0.
  const dpc::PropagationSettings settings = engine->scene.propagation;
  engine->session = std::make_unique<dpc::LiveSession>(
      std::make_shared<const dpc::SceneDesc>(std::move(engine->scene)), settings,
      std::make_shared<const dpc::DrySignals>(std::move(engine->dry)), options);
  return engine.release();
}

}  // namespace

extern "C" {

const char* dpc_last_error(void) {
  return lastError.c_str();
}

const char* dpc_version(void) {
  return DPC_VERSION_STRING;
}

dpc_status dpc_engine_create_from_file(const char* scene_path, dpc_engine** out) {
  return dpc_engine_create_from_file_ex(scene_path, nullptr, out);
}

void dpc_engine_options_init(dpc_engine_options* options) {
  if (options) *options = dpc_engine_options{};
}

dpc_status dpc_engine_create_from_file_ex(const char* scene_path, const dpc_engine_options* options,
                                          dpc_engine** out) {
  if (!out) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_file: out is NULL");
  *out = nullptr;
  if (!scene_path)
    return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_file: scene_path is NULL");
  return guarded([&] {
    auto engine = std::make_unique<dpc_engine>();
    engine->scene = dpc::loadScene(scene_path);
    if (const char* bad = applyOptions(options, engine->scene))
      return fail(DPC_ERR_INVALID_ARGUMENT, bad);
    if (options && options->host_inputs_only)
      for (auto& src : engine->scene.sources) src.signalPath.clear();
    engine->dry = dpc::loadDrySignals(engine->scene);
    *out = finish(std::move(engine));
    return DPC_OK;
  });
}

void dpc_scene_data_init(dpc_scene_data* data) {
  if (!data) return;
  *data = dpc_scene_data{};
  const dpc::PropagationSettings p;
  const dpc::AudioSettings a;
  const dpc::ListenerDesc l;
  data->listener_radius = l.radius;
  data->rays_per_frame = p.raysPerFrame;
  data->max_order = p.maxOrder;
  data->patch_size = p.patchSize;
  data->cache_tau = p.cacheTau;
  data->frame_rate = p.frameRate;
  data->ir_length = p.irLength;
  data->seed = p.seed;
  data->speed_of_sound = 0.f;
  data->temperature = p.temperatureC;
  data->humidity = p.humidityPercent;
  data->air_absorption = p.airAbsorption ? 1 : 0;
  data->diffraction = p.diffraction ? 1 : 0;
  data->sample_rate = a.sampleRate;
  data->block_size = a.blockSize;
  data->output = DPC_OUTPUT_MONO;
}

dpc_status dpc_engine_create_from_data(const dpc_scene_data* data,
                                       const dpc_engine_options* options, dpc_engine** out) {
  if (!out) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_data: out is NULL");
  *out = nullptr;
  if (!data) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_data: data is NULL");
  return guarded([&] {
    auto engine = std::make_unique<dpc_engine>();
    engine->scene = sceneFromData(*data);
    if (const char* bad = applyOptions(options, engine->scene))
      return fail(DPC_ERR_INVALID_ARGUMENT, bad);
    const bool hostOnly = options && options->host_inputs_only;
    for (int i = 0; i < data->source_count; ++i) {
      const dpc_source& src = data->sources[i];
      std::vector<float> x;
      if (!hostOnly && src.signal) {
        const float gain = float(std::pow(10.0, src.gain_db / 20.0));
        x.assign(src.signal, src.signal + src.signal_frames);
        for (float& v : x) v *= gain;
      }
      engine->dry.loop.push_back(src.loop && !x.empty() ? 1 : 0);
      engine->dry.samples.push_back(std::move(x));
    }
    *out = finish(std::move(engine));
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
  // Any thread: no message on failure (setting it would allocate).
  if (!engine) return DPC_ERR_INVALID_ARGUMENT;
  for (float v : {x, y, z, yaw_degrees, pitch_degrees})
    if (!std::isfinite(v)) return DPC_ERR_INVALID_ARGUMENT;
  engine->session->setPose(glm::vec3(x, y, z), yaw_degrees * kDegrees, 0.0,
                           pitch_degrees * kDegrees);
  return DPC_OK;
}

int dpc_engine_listener_count(const dpc_engine* engine) {
  return engine ? int(engine->session->listenerCount()) : 0;
}

dpc_status dpc_engine_set_listener_pose(dpc_engine* engine, int listener, float x, float y,
                                        float z, float yaw_degrees, float pitch_degrees) {
  // Any thread: no message on failure (setting it would allocate).
  if (!engine || listener < 0) return DPC_ERR_INVALID_ARGUMENT;
  for (float v : {x, y, z, yaw_degrees, pitch_degrees})
    if (!std::isfinite(v)) return DPC_ERR_INVALID_ARGUMENT;
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
  if (!engine || object < 0 || object >= engine->session->objectCount())
    return DPC_ERR_INVALID_ARGUMENT;
  const float q[4] = {qx, qy, qz, qw};
  for (float v : {x, y, z, qx, qy, qz, qw})
    if (!std::isfinite(v)) return DPC_ERR_INVALID_ARGUMENT;
  return engine->session->setObjectPose(size_t(object), glm::vec3(x, y, z), q)
             ? DPC_OK
             : DPC_ERR_INVALID_ARGUMENT;
}

dpc_status dpc_engine_step(dpc_engine* engine) {
  if (!engine) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_step: engine is NULL");
  return guarded([&] {
    return engine->session->step()
               ? DPC_OK
               : fail(DPC_ERR_STATE, "dpc_engine_step: the propagation thread is running");
  });
}

dpc_status dpc_engine_copy_impulse_response(dpc_engine* engine, int source, int channel, float* out,
                                            size_t capacity, size_t* length, uint64_t* frame) {
  if (!engine || source < 0 || source >= engine->sources || channel < 0 ||
      channel >= engine->session->irChannels() || (!out && capacity > 0))
    return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_copy_impulse_response: bad argument");
  const bool ok = engine->session->copyResponses(size_t(source), [&](const auto& r) {
    const std::vector<float>& ir = (*r.ir)[size_t(channel)];
    if (length) *length = ir.size();
    if (frame) *frame = r.frame;
    if (out && capacity > 0)
      std::memcpy(out, ir.data(), std::min(capacity, ir.size()) * sizeof(float));
  });
  return ok ? DPC_OK
            : fail(DPC_ERR_STATE, "dpc_engine_copy_impulse_response: no propagation frame yet");
}

dpc_status dpc_engine_copy_energy_response(dpc_engine* engine, int source, float* out,
                                           size_t capacity_bins, size_t* bins, double* bin_seconds,
                                           uint64_t* frame) {
  if (!engine || source < 0 || source >= engine->sources || (!out && capacity_bins > 0))
    return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_copy_energy_response: bad argument");
  static_assert(DPC_BANDS == dpc::kNumBands, "band count of the public API");
  const bool ok = engine->session->copyResponses(size_t(source), [&](const auto& r) {
    if (bins) *bins = r.energy->size();
    if (bin_seconds) *bin_seconds = r.binSeconds;
    if (frame) *frame = r.frame;
    const size_t n = std::min(capacity_bins, r.energy->size());
    for (size_t k = 0; k < n; ++k)
      for (int b = 0; b < DPC_BANDS; ++b) out[k * DPC_BANDS + size_t(b)] = (*r.energy)[k][b];
  });
  return ok ? DPC_OK
            : fail(DPC_ERR_STATE, "dpc_engine_copy_energy_response: no propagation frame yet");
}

dpc_status dpc_engine_process(dpc_engine* engine, const float* const* inputs, float* const* outputs,
                              int frames) {
  dpc::audio::rt::enterAudioThread();  // the host's audio thread (audio/rt_check.h)
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
  return e ? e->session->objectCount() : 0;
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
    out->rays_per_frame = int32_t(s.raysPerFrame);
    out->rays_per_frame_min = int32_t(s.raysPerFrameMin);
    out->reduced_frames = s.reducedFrames;
    return DPC_OK;
  });
}

}  // extern "C"
