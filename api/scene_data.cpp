#include "api/scene_data.h"

#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <string>

#include "common/air_absorption.h"
#include "common/input_error.h"

namespace dpc::api {
namespace {

// One-line error for scene data, in the loader's "FILE: FIELD: problem" form.
[[noreturn]] void bad(const std::string& field, const std::string& problem) {
  throw InputError("dpc_scene_data", field, problem);
}

void checkFinite(float v, const std::string& field) {
  if (!std::isfinite(v)) bad(field, "not a finite number");
}

void checkRange(double v, double lo, double hi, const std::string& field, const char* unit) {
  if (!(v >= lo && v <= hi))
    bad(field, std::to_string(v) + " is outside [" + std::to_string(lo) + ", " +
                   std::to_string(hi) + "]" + unit);
}

void addMaterials(const dpc_scene_data& d, SceneDesc& scene) {
  if (d.material_count < 1 || !d.materials) bad("materials", "at least one material is required");
  for (int i = 0; i < d.material_count; ++i) {
    const dpc_material& m = d.materials[i];
    const std::string f = "materials[" + std::to_string(i) + "]";
    Material mat;
    mat.name = m.name ? m.name : "material " + std::to_string(i);
    for (int b = 0; b < DPC_BANDS; ++b) {
      checkRange(m.absorption[b], 0.0, 1.0, f + ".absorption[" + std::to_string(b) + "]", "");
      mat.absorption[b] = m.absorption[b];
    }
    checkRange(m.scattering, 0.0, 1.0, f + ".scattering", "");
    mat.scattering = Bands(m.scattering);
    scene.materials.push_back(mat);
  }
}

void addVertices(const dpc_mesh& mesh, SceneDesc& scene) {
  for (uint32_t v = 0; v < mesh.vertex_count; ++v) {
    const float* p = mesh.vertices + size_t(v) * 3;
    for (int k = 0; k < 3; ++k)
      checkFinite(p[k], "mesh.vertices[" + std::to_string(size_t(v) * 3 + size_t(k)) + "]");
    scene.mesh.vertices.emplace_back(p[0], p[1], p[2]);
  }
}

void addTriangles(const dpc_scene_data& d, SceneDesc& scene) {
  const dpc_mesh& mesh = d.mesh;
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
}

void addMesh(const dpc_scene_data& d, SceneDesc& scene) {
  const dpc_mesh& mesh = d.mesh;
  if (mesh.triangle_count == 0 || !mesh.vertices || !mesh.indices || !mesh.materials)
    bad("mesh", "vertices, indices and materials are required, with triangle_count > 0");
  addVertices(mesh, scene);
  addTriangles(d, scene);
}

void addSources(const dpc_scene_data& d, SceneDesc& scene) {
  if (d.source_count < 1 || !d.sources) bad("sources", "at least one source is required");
  for (int i = 0; i < d.source_count; ++i) {
    const dpc_source& s = d.sources[i];
    const std::string f = "sources[" + std::to_string(i) + "]";
    SourceDesc src;
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
}

void addFirstListener(const dpc_scene_data& d, SceneDesc& scene) {
  ListenerDesc l;
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
  scene.listener = l;
}

void addAdditionalListeners(const dpc_scene_data& d, SceneDesc& scene) {
  if (d.additional_listener_count < 0 || d.additional_listener_count > 63)
    bad("additional_listener_count", "must be in 0..63");
  if (d.additional_listener_count > 0 && !d.additional_listeners)
    bad("additional_listeners", "NULL with additional_listener_count > 0");
  for (int i = 0; i < d.additional_listener_count; ++i) {
    const dpc_listener& a = d.additional_listeners[i];
    const std::string f = "additional_listeners[" + std::to_string(i) + "]";
    ListenerDesc extra;
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
}

// Bounds of the scene file's "propagation" (scene/scene.cpp).
void setPropagation(const dpc_scene_data& d, SceneDesc& scene) {
  PropagationSettings& p = scene.propagation;
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
    p.speedOfSound = float(speedOfSoundAt(p.temperatureC));
  } else {
    checkRange(d.speed_of_sound, 1.0, 10000.0, "speed_of_sound", " m/s");
    p.speedOfSound = d.speed_of_sound;
  }
  p.airAbsorption = d.air_absorption != 0;
  p.diffraction = d.diffraction != 0;
}

// Bounds of the scene file's "audio" (scene/scene.cpp).
void setAudio(const dpc_scene_data& d, SceneDesc& scene) {
  checkRange(d.sample_rate, 8000, 384000, "sample_rate", " Hz");
  checkRange(d.block_size, 16, 8192, "block_size", " frames");
  scene.audio.sampleRate = d.sample_rate;
  scene.audio.blockSize = d.block_size;
  if (!toOutputFormat(d.output, &scene.audio.output))
    bad("output", "must be DPC_OUTPUT_MONO, _STEREO or _BINAURAL");
}

}  // namespace

bool toOutputFormat(dpc_output_format format, OutputFormat* out) {
  switch (format) {
    case DPC_OUTPUT_MONO:
      *out = OutputFormat::kMono;
      return true;
    case DPC_OUTPUT_STEREO:
      *out = OutputFormat::kStereo;
      return true;
    case DPC_OUTPUT_BINAURAL:
      *out = OutputFormat::kBinaural;
      return true;
    default:
      return false;
  }
}

SceneDesc sceneFromData(const dpc_scene_data& d) {
  SceneDesc scene;
  scene.path = "dpc_scene_data";
  addMaterials(d, scene);
  addMesh(d, scene);
  addSources(d, scene);
  addFirstListener(d, scene);
  addAdditionalListeners(d, scene);
  setPropagation(d, scene);
  setAudio(d, scene);
  return scene;
}

DrySignals drySignalsFromData(const dpc_scene_data& data, bool hostInputsOnly) {
  DrySignals dry;
  for (int i = 0; i < data.source_count; ++i) {
    const dpc_source& src = data.sources[i];
    std::vector<float> x;
    if (!hostInputsOnly && src.signal) {
      const float gain = float(std::pow(10.0, src.gain_db / 20.0));
      x.assign(src.signal, src.signal + src.signal_frames);
      for (float& v : x) v *= gain;
    }
    dry.loop.push_back(src.loop && !x.empty() ? 1 : 0);
    dry.samples.push_back(std::move(x));
  }
  return dry;
}

}  // namespace dpc::api

extern "C" void dpc_scene_data_init(dpc_scene_data* data) {
  if (!data) return;
  *data = dpc_scene_data{};
  data->struct_size = sizeof(dpc_scene_data);
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
