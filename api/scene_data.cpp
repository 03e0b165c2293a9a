#include "api/scene_data.h"

#include <array>
#include <cmath>
#include <cstring>
#include <glm/geometric.hpp>
#include <string>
#include <type_traits>

#include "api/errors.h"
#include "api/field_names.h"
#include "api/layouts.h"
#include "common/air_absorption.h"
#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/mesh_builder.h"
#include "scene/quaternion.h"
#include "scene/validate.h"

namespace dpc::api {
namespace {

// One-line error for scene data, in the loader's "FILE: FIELD: problem" form.
[[noreturn]] void bad(const std::string& field, const std::string& problem) {
  throw InputError("dpc_scene_data", field, problem);
}

// The same for a NULL pointer where a count says there is data: DPC_ERR_INVALID_ARGUMENT.
[[noreturn]] void nullField(const std::string& field, const std::string& problem) {
  throw NullArgument("dpc_scene_data", field, "NULL with " + problem);
}

glm::vec3 vec3(const float* p) {
  return glm::vec3(p[0], p[1], p[2]);
}

void materialsFromData(const dpc_scene_data& d, SceneDesc& scene) {
  if (d.material_count < 1) bad("materials", "at least one material is required");
  if (!d.materials) nullField("materials", "material_count " + std::to_string(d.material_count));
  for (int i = 0; i < d.material_count; ++i) {
    const dpc_material& m = d.materials[i];
    Material mat;
    mat.name = m.name ? m.name : "material " + std::to_string(i);
    for (int b = 0; b < DPC_BANDS; ++b) mat.absorption[b] = m.absorption[b];
    mat.scattering = Bands(m.scattering);
    if (d.material_transmissions)  // validate() checks the range and tau <= alpha
      for (int b = 0; b < DPC_BANDS; ++b)
        mat.transmissionLossDb[b] = d.material_transmissions[i].loss_db[b];
    scene.materials.push_back(mat);
  }
}

// The mesh as given (validate() checks its indices), then cleaned by the one mesh builder.
void meshFromData(const dpc_mesh& mesh, Mesh& out) {
  if (mesh.triangle_count == 0) bad("mesh", "at least one triangle is required");
  const std::string counts = "triangle_count " + std::to_string(mesh.triangle_count);
  if (!mesh.indices) nullField("mesh.indices", counts);
  if (!mesh.materials) nullField("mesh.materials", counts);
  if (!mesh.vertices && mesh.vertex_count > 0)
    nullField("mesh.vertices", "vertex_count " + std::to_string(mesh.vertex_count));
  for (uint32_t v = 0; v < mesh.vertex_count; ++v)
    out.vertices.push_back(vec3(mesh.vertices + 3 * size_t(v)));
  for (uint32_t t = 0; t < mesh.triangle_count; ++t) {
    const uint32_t* i = mesh.indices + 3 * size_t(t);
    out.triangles.push_back({i[0], i[1], i[2]});
    out.materialIndex.push_back(mesh.materials[t]);
  }
}

Mesh cleanMesh(const Mesh& mesh, std::vector<std::string>& warnings) {
  RawMesh raw;
  raw.file = "dpc_scene_data";
  raw.faceWord = "triangle";
  raw.positions = mesh.vertices;
  raw.triangles = mesh.triangles;
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) raw.triangleFace.push_back(t);
  return buildMesh(raw, mesh.materialIndex, warnings);
}

/// Source i's pattern and rotation; the pattern's range is checked by validate().
void directivityFromData(const dpc_source_directivity& d, int i, SourceDesc& src) {
  for (int b = 0; b < kNumBands; ++b) src.directivity.a[b] = d.a[b];
  const auto q = unitQuaternion(d.rotation[0], d.rotation[1], d.rotation[2], d.rotation[3]);
  if (!q)
    bad("source_directivities[" + std::to_string(i) + "].rotation",
        "zero length (or not finite); a rotation needs a unit quaternion");
  src.rotation = *q;
}

void sourcesFromData(const dpc_scene_data& d, const Origin& origin, SceneDesc& scene) {
  if (d.source_count < 1) bad("sources", "at least one source is required");
  if (!d.sources) nullField("sources", "source_count " + std::to_string(d.source_count));
  checkField("sources", d.source_count, origin);
  for (int i = 0; i < d.source_count; ++i) {
    const dpc_source& s = d.sources[i];
    const std::string f = "sources[" + std::to_string(i) + "]";
    SourceDesc src;
    src.name = "source " + std::to_string(i);
    src.position = vec3(s.position);
    src.gainDb = s.gain_db;
    src.loop = s.loop != 0;
    if (!s.signal && s.signal_frames > 0)
      nullField(f + ".signal", "signal_frames " + std::to_string(s.signal_frames));
    for (size_t n = 0; n < s.signal_frames; ++n)
      if (const std::string why = sampleProblem(s.signal[n]); !why.empty())
        bad(f + ".signal", "sample " + std::to_string(n) + " " + why);
    if (d.source_directivities) directivityFromData(d.source_directivities[i], i, src);
    scene.sources.push_back(src);
  }
}

void listenersFromData(const dpc_scene_data& d, const Origin& origin, SceneDesc& scene) {
  checkField("listeners", 1.0 + d.additional_listener_count, origin);
  if (d.additional_listener_count > 0 && !d.additional_listeners)
    nullField("additional_listeners",
              "additional_listener_count " + std::to_string(d.additional_listener_count));
  dpc_listener first{};
  std::memcpy(first.position, d.listener_position, sizeof first.position);
  first.radius = d.listener_radius;
  first.yaw_degrees = d.listener_yaw_degrees;
  first.pitch_degrees = d.listener_pitch_degrees;
  first.roll_degrees = d.listener_roll_degrees;
  for (int i = 0; i <= d.additional_listener_count; ++i) {
    const dpc_listener& a = i == 0 ? first : d.additional_listeners[i - 1];
    ListenerDesc l;
    l.name = "listener " + std::to_string(i);
    l.position = vec3(a.position);
    l.radius = a.radius;
    l.yawDegrees = a.yaw_degrees;
    l.pitchDegrees = a.pitch_degrees;
    l.rollDegrees = a.roll_degrees;
    scene.listeners.push_back(l);
  }
}

/// The rendering of a raw enum value (any bit pattern a caller may store); false if unknown.
bool toRendering(const dpc_rendering& field, Rendering* out) {
  switch (rawEnum(field)) {
    case DPC_RENDERING_AUTO:
      *out = Rendering::kAuto;
      return true;
    case DPC_RENDERING_PER_SOURCE:
      *out = Rendering::kPerSource;
      return true;
    case DPC_RENDERING_HYBRID:
      *out = Rendering::kHybrid;
      return true;
    default:
      return false;
  }
}

/// The 0.8.0 fields: estimator, tracing, reflection scattering and the roulette threshold.
void propagationChoicesFromData(const dpc_scene_data& d, const Origin& origin,
                                PropagationSettings& p) {
  const long estimator = rawEnum(d.estimator), tracing = rawEnum(d.tracing);
  if (estimator != DPC_ESTIMATOR_DPC && estimator != DPC_ESTIMATOR_PATH_TRACING)
    bad("estimator", "must be DPC_ESTIMATOR_DPC or DPC_ESTIMATOR_PATH_TRACING");
  p.estimator = estimator == DPC_ESTIMATOR_DPC ? Estimator::kDpc : Estimator::kPathTracing;
  if (tracing == DPC_TRACING_AUTO)
    p.tracing = Tracing::kAuto;
  else if (tracing == DPC_TRACING_FROM_SOURCES)
    p.tracing = Tracing::kFromSources;
  else if (tracing == DPC_TRACING_FROM_LISTENERS)
    p.tracing = Tracing::kFromListeners;
  else
    bad("tracing", "must be DPC_TRACING_AUTO, _FROM_SOURCES or _FROM_LISTENERS");
  p.reflectionScattering = d.reflection_scattering != 0;
  checkField("propagation.roulette_threshold_db", d.roulette_threshold_db, origin);
  p.rouletteThreshold = float(std::pow(10.0, double(d.roulette_threshold_db) / 10.0));
}

void settingsFromData(const dpc_scene_data& d, const Origin& origin, SceneDesc& scene) {
  PropagationSettings& p = scene.propagation;
  p.raysPerFrame = d.rays_per_frame;
  p.maxOrder = d.max_order;
  p.patchSize = d.patch_size;
  p.cacheTau = d.cache_tau;
  p.frameRate = d.frame_rate;
  p.irLength = d.ir_length;
  p.seed = d.seed;
  p.temperatureC = d.temperature;
  p.humidityPercent = d.humidity;
  p.speedOfSound =
      d.speed_of_sound == 0.f ? float(speedOfSoundAt(p.temperatureC)) : d.speed_of_sound;
  p.airAbsorption = d.air_absorption != 0;
  p.diffraction = d.diffraction != 0;
  scene.audio.sampleRate = d.sample_rate;
  scene.audio.blockSize = d.block_size;
  if (!toOutputFormat(d.output, &scene.audio.output))
    bad("output",
        "must be DPC_OUTPUT_MONO, _STEREO, _BINAURAL, _AMBISONICS or _AMBISONIC_BINAURAL");
  scene.audio.ambisonicOrder = d.ambisonic_order;
  static_assert(DPC_CACHE_POOL_AUTO == kCachePoolAuto);
  p.cachePoolMb = d.cache_pool_mb;
  scene.audio.lateBuses = d.late_buses;
  scene.audio.clusterAngleDegrees = d.cluster_angle_degrees;
  p.exactOrder = d.exact_order;
  if (!toRendering(d.rendering, &scene.audio.rendering))
    bad("rendering", "must be DPC_RENDERING_AUTO, _PER_SOURCE or _HYBRID");
  propagationChoicesFromData(d, origin, p);
}

}  // namespace

bool toOutputFormat(const dpc_output_format& field, OutputFormat* out) {
  const long raw = rawEnum(field);
  if (raw == DPC_OUTPUT_MONO) {
    *out = OutputFormat::kMono;
  } else if (raw == DPC_OUTPUT_STEREO) {
    *out = OutputFormat::kStereo;
  } else if (raw == DPC_OUTPUT_BINAURAL) {
    *out = OutputFormat::kBinaural;
  } else if (raw == DPC_OUTPUT_AMBISONICS) {
    *out = OutputFormat::kAmbisonics;
  } else if (raw == DPC_OUTPUT_AMBISONIC_BINAURAL) {
    *out = OutputFormat::kAmbisonicBinaural;
  } else {
    return false;
  }
  return true;
}

// The SceneDesc a scene file with the same content would give (docs/scene-format.md),
// checked by the same validate() and cleaned by the same mesh builder.
SceneDesc sceneFromData(const dpc_scene_data& d) {
  SceneDesc scene;
  scene.path = "dpc_scene_data";
  const Origin origin = apiOrigin("dpc_scene_data", scene);
  materialsFromData(d, scene);
  meshFromData(d.mesh, scene.mesh);
  sourcesFromData(d, origin, scene);
  listenersFromData(d, origin, scene);
  settingsFromData(d, origin, scene);
  validate(scene, origin);
  scene.mesh = cleanMesh(scene.mesh, scene.warnings);
  return scene;
}

DrySignals drySignalsFromData(const dpc_scene_data& data, bool hostInputsOnly) {
  DrySignals dry;
  for (int i = 0; i < data.source_count; ++i) {
    const dpc_source& src = data.sources[i];
    std::vector<float> x;
    dry.gain.push_back(gainOfDb(src.gain_db));
    if (!hostInputsOnly && src.signal) {
      x.assign(src.signal, src.signal + src.signal_frames);
      for (float& v : x) v *= dry.gain.back();
    }
    dry.loop.push_back(src.loop && !x.empty() ? 1 : 0);
    dry.samples.push_back(std::move(x));
  }
  return dry;
}

dpc_scene_data defaultSceneData() {
  dpc_scene_data d{};
  d.struct_size = sizeof(dpc_scene_data);
  const PropagationSettings p;
  const AudioSettings a;
  const ListenerDesc l;
  d.listener_radius = l.radius;
  d.rays_per_frame = p.raysPerFrame;
  d.max_order = p.maxOrder;
  d.patch_size = p.patchSize;
  d.cache_tau = p.cacheTau;
  d.frame_rate = p.frameRate;
  d.ir_length = p.irLength;
  d.seed = p.seed;
  d.speed_of_sound = 0.f;
  d.temperature = p.temperatureC;
  d.humidity = p.humidityPercent;
  d.air_absorption = p.airAbsorption ? 1 : 0;
  d.diffraction = p.diffraction ? 1 : 0;
  d.sample_rate = a.sampleRate;
  d.block_size = a.blockSize;
  d.output = DPC_OUTPUT_MONO;
  d.cache_pool_mb = p.cachePoolMb;
  d.rendering = DPC_RENDERING_AUTO;
  d.late_buses = a.lateBuses;
  d.cluster_angle_degrees = a.clusterAngleDegrees;
  d.ambisonic_order = a.ambisonicOrder;
  d.material_transmissions = nullptr;
  d.exact_order = p.exactOrder;
  d.reserved_0_7 = 0;
  d.estimator = p.estimator == Estimator::kDpc ? DPC_ESTIMATOR_DPC : DPC_ESTIMATOR_PATH_TRACING;
  d.tracing = DPC_TRACING_AUTO;
  static_assert(PropagationSettings{}.tracing == Tracing::kAuto);
  d.reflection_scattering = p.reflectionScattering ? 1 : 0;
  d.roulette_threshold_db = float(10.0 * std::log10(double(p.rouletteThreshold)));
  return d;
}

}  // namespace dpc::api

extern "C" {

dpc_status dpc_scene_data_init_sized(dpc_scene_data* data, size_t struct_size) {
  if (!data)
    return dpc::api::failFixed(DPC_ERR_INVALID_ARGUMENT, "dpc_scene_data_init", "data is NULL");
  return dpc::api::writeVersioned(data, struct_size, dpc::api::defaultSceneData());
}

void(dpc_scene_data_init)(dpc_scene_data* data) {
  if (data)
    dpc_scene_data_init_sized(data, dpc::api::Layouts<dpc_scene_data>::kPlainInitSize);
}

}  // extern "C"
