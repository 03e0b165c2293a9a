// Engine lifetime across the C API: options, creation from a scene file or from scene data,
// destruction, start, stop and single frames (include/dpc/dpc.h).
#include <memory>
#include <string>
#include <utility>

#include "api/engine_handle.h"
#include "api/errors.h"
#include "api/field_names.h"
#include "api/layouts.h"
#include "api/scene_data.h"
#include "common/input_error.h"
#include "common/log.h"
#include "engine/workload.h"
#include "runtime/output_format.h"
#include "scene/validate.h"

namespace dpc::api {
namespace {

dpc_engine_options defaultOptions() {
  dpc_engine_options o{};
  o.struct_size = sizeof o;
  return o;
}

// Applies dpc_engine_options (NULL: none; of the current layout, readOptions) to a loaded
// scene and validates the result with the scene file's limits (scene/validate.h); DPC_OK or the
// failure with its one-line message.
dpc_status applyOptions(const dpc_engine_options* o, SceneDesc& scene) {
  if (!o) return DPC_OK;
  if (o->sample_rate != 0) scene.audio.sampleRate = o->sample_rate;
  if (o->block_size != 0) scene.audio.blockSize = o->block_size;
  if (o->rays_per_frame != 0) scene.propagation.raysPerFrame = o->rays_per_frame;
  if (o->ambisonic_order != 0) scene.audio.ambisonicOrder = o->ambisonic_order;
  if (o->ir_length != 0.f) scene.propagation.irLength = o->ir_length;
  try {
    validate(scene, apiOrigin("dpc_engine_options", scene));
  } catch (const InputError& e) {
    return fail(DPC_ERR_INVALID_ARGUMENT, e.what());
  }
  // Checked after the values, so that a bad value's message wins.
  if (rawEnum(o->output) != DPC_OUTPUT_SCENE &&
      !toOutputFormat(o->output, &scene.audio.output))
    return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_options.output: not a dpc_output_format");
  return DPC_OK;
}

// The caller's options (NULL: none) at the current layout in *full, the fields of later
// releases than the caller's at their defaults; *given says whether there were any.
// DPC_ERR_VERSION for an unknown layout.
dpc_status readOptions(const dpc_engine_options* caller, dpc_engine_options* full, bool* given) {
  *given = caller != nullptr;
  return caller ? readVersioned(caller, defaultOptions(), full) : DPC_OK;
}

}  // namespace

/// The work and memory estimate of dpc-demo's preflight (engine/workload.h) for a live engine
/// holding `dry`: a frame beyond reach, or impulse responses, path caches and signals beyond
/// the memory available, throw InputError naming the setting to lower, instead of running out
/// of memory part-way.
void checkEngineWorkload(const SceneDesc& scene, const DrySignals& dry) {
  WorkloadEstimate e = estimateWorkload(scene, scene.propagation,
                                        irChannels(scene.audio), 0.0);
  for (const std::vector<float>& x : dry.samples) e.signalBytes += double(x.size() * sizeof(float));
  checkWorkload(scene, scene.propagation, e, plannableMemoryBytes());
}

dpc_engine* finishEngine(std::unique_ptr<dpc_engine> engine) {
  checkEngineWorkload(engine->scene, engine->dry);
  for (const std::string& w : engine->scene.warnings) logMessage(LogLevel::kWarning, w);
  engine->sources = int(engine->scene.sources.size());
  LiveSession::Options options;
  options.deviceChannels = renderedChannels(engine->scene.audio);
  // The session shares the scene and the signals; until the host sets a pose, every listener
  // stands where the scene puts it at time 0.
  const PropagationSettings settings = engine->scene.propagation;
  engine->session = std::make_unique<LiveSession>(
      std::make_shared<const SceneDesc>(std::move(engine->scene)), settings,
      std::make_shared<const DrySignals>(std::move(engine->dry)), options);
  return engine.release();
}

}  // namespace dpc::api

using dpc::api::EngineCall;
using dpc::api::fail;
using dpc::api::guarded;
using dpc::api::Layouts;

extern "C" {

dpc_status dpc_engine_options_init_sized(dpc_engine_options* options, size_t struct_size) {
  if (!options)
    return dpc::api::failFixed(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_options_init",
                               "options is NULL");
  return dpc::api::writeVersioned(options, struct_size, dpc::api::defaultOptions());
}

void(dpc_engine_options_init)(dpc_engine_options* options) {
  if (options)
    dpc_engine_options_init_sized(options, Layouts<dpc_engine_options>::kPlainInitSize);
}

dpc_status dpc_engine_create_from_file(const char* scene_path, const dpc_engine_options* options,
                                       dpc_engine** out) {
  if (!out) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_file: out is NULL");
  *out = nullptr;
  if (!scene_path)
    return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_file: scene_path is NULL");
  dpc_engine_options o;
  bool given = false;
  if (const dpc_status s = dpc::api::readOptions(options, &o, &given); s != DPC_OK) return s;
  return guarded([&] {
    auto engine = std::make_unique<dpc_engine>();
    engine->scene = dpc::loadScene(scene_path);
    if (const dpc_status s = dpc::api::applyOptions(given ? &o : nullptr, engine->scene);
        s != DPC_OK)
      return s;
    if (given && o.host_inputs_only)
      for (auto& src : engine->scene.sources) src.signalPath.clear();
    engine->dry = dpc::loadDrySignals(engine->scene);
    *out = dpc::api::finishEngine(std::move(engine));
    return DPC_OK;
  });
}

dpc_status dpc_engine_create_from_data(const dpc_scene_data* data,
                                       const dpc_engine_options* options, dpc_engine** out) {
  if (!out) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_data: out is NULL");
  *out = nullptr;
  if (!data) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_engine_create_from_data: data is NULL");
  dpc_scene_data d;
  if (const dpc_status s = dpc::api::readVersioned(data, dpc::api::defaultSceneData(), &d);
      s != DPC_OK)
    return s;
  dpc_engine_options o;
  bool given = false;
  if (const dpc_status s = dpc::api::readOptions(options, &o, &given); s != DPC_OK) return s;
  return guarded([&] {
    auto engine = std::make_unique<dpc_engine>();
    engine->scene = dpc::api::sceneFromData(d);
    if (const dpc_status s = dpc::api::applyOptions(given ? &o : nullptr, engine->scene);
        s != DPC_OK)
      return s;
    engine->dry = dpc::api::drySignalsFromData(d, given && o.host_inputs_only);
    *out = dpc::api::finishEngine(std::move(engine));
    return DPC_OK;
  });
}

void dpc_engine_destroy(dpc_engine* engine) {
  if (engine) dpc::api::destroyEngine(engine);
}

dpc_status dpc_engine_start(dpc_engine* engine) {
  const EngineCall call(engine);
  if (const dpc_status s = call.check("dpc_engine_start"); s != DPC_OK) return s;
  return guarded([&] {
    engine->session->start();
    return DPC_OK;
  });
}

dpc_status dpc_engine_stop(dpc_engine* engine) {
  const EngineCall call(engine);
  if (const dpc_status s = call.check("dpc_engine_stop"); s != DPC_OK) return s;
  return guarded([&] {
    engine->session->stop();
    return DPC_OK;
  });
}

dpc_status dpc_engine_step(dpc_engine* engine) {
  const EngineCall call(engine);
  if (const dpc_status s = call.check("dpc_engine_step"); s != DPC_OK) return s;
  return guarded([&] {
    return engine->session->step()
               ? DPC_OK
               : fail(DPC_ERR_STATE, "dpc_engine_step: the propagation thread is running");
  });
}

}  // extern "C"
