#include "scene/validate.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <utility>

#include "common/input_error.h"
#include "scene/limits.h"
#include "scene/transmission.h"

namespace dpc {
namespace {

std::string at(const std::string& parent, size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

[[noreturn]] void fail(const Origin& origin, const std::string& path, const std::string& why) {
  throw InputError(origin.name, origin.fieldName(path), why);
}

void checkPosition(const glm::vec3& p, const Origin& origin, const std::string& path) {
  for (int k = 0; k < 3; ++k) checkField("position", double(p[k]), origin, at(path, size_t(k)));
}

void checkBands(const char* field, const Bands& b, const Origin& origin, const std::string& path) {
  for (int k = 0; k < kNumBands; ++k) checkField(field, double(b[k]), origin, at(path, size_t(k)));
}

/// A rotation must be a unit quaternion (within float rounding); NaN never is.
void checkRotation(const glm::quat& q, const Origin& origin, const std::string& path) {
  const float n = glm::dot(q, q);
  if (!(std::abs(n - 1.f) < 1e-3f))
    fail(origin, path, "not a unit quaternion (squared length " + valueText(n) + ")");
}

/// Keyframe times: finite, >= 0, strictly increasing.
template <class Keys>
void checkKeyTimes(const Keys& keys, const Origin& origin, const std::string& path) {
  for (size_t i = 0; i < keys.size(); ++i) {
    const double t = keys[i].timeSeconds;
    const std::string f = at(path, i) + ".t";
    if (!(t >= 0.0) || !std::isfinite(t)) fail(origin, f, valueText(t) + " must be >= 0");
    if (i > 0 && !(t > keys[i - 1].timeSeconds))
      fail(origin, f,
           valueText(t) + " is not greater than the previous keyframe's t (" +
               valueText(keys[i - 1].timeSeconds) + "); times must be strictly increasing");
  }
}

template <class Items>
void checkNames(const Items& items, const char* field, const char* what, const Origin& origin,
                bool namesFile = false) {
  std::set<std::string> seen;
  for (size_t i = 0; i < items.size(); ++i) {
    const std::string f = at(field, i) + ".name";
    checkName(items[i].name, namesFile, origin, f);
    if (!seen.insert(items[i].name).second)
      fail(origin, f, std::string("duplicate ") + what + " name \"" + items[i].name + "\"");
  }
}

/// R within its limit (or +infinity, opaque) per band, and tau = 10^(-R/10) <= alpha: the
/// transmitted part is a share of what alpha counts as absorbed (scene/transmission.h).
void checkTransmission(const Material& m, const Origin& origin, const std::string& path) {
  const Bands tau = transmittanceOf(m.transmissionLossDb);
  for (int k = 0; k < kNumBands; ++k) {
    const double r = double(m.transmissionLossDb[k]);
    if (std::isinf(r) && r > 0.0) continue;
    checkField("materials.*.transmission_loss_db", r, origin, at(path, size_t(k)));
    if (tau[k] > m.absorption[k])
      fail(origin, at(path, size_t(k)),
           valueText(r) + " dB transmits tau = " + valueText(tau[k]) +
               ", more than the absorption " + valueText(m.absorption[k]) +
               " (alpha counts the transmitted part: tau <= alpha)");
  }
}

void checkMaterials(const std::vector<Material>& materials, const Origin& origin) {
  if (materials.empty()) fail(origin, "materials", "at least one material is required");
  for (const Material& m : materials) {
    const std::string f = "materials." + m.name;
    checkName(m.name, false, origin, f);
    checkBands("materials.*.absorption", m.absorption, origin, f + ".absorption");
    checkBands("materials.*.scattering", m.scattering, origin, f + ".scattering");
    checkTransmission(m, origin, f + ".transmission_loss_db");
  }
}

void checkPropagation(const PropagationSettings& p, const Origin& origin) {
  checkField("propagation.rays_per_frame", p.raysPerFrame, origin);
  checkField("propagation.max_order", p.maxOrder, origin);
  checkField("propagation.exact_order", p.exactOrder, origin);
  checkField("propagation.patch_size", p.patchSize, origin);
  checkField("propagation.cache_tau", p.cacheTau, origin);
  checkField("propagation.cache_memory_mb", p.cacheMemoryMb, origin);
  if (p.cachePoolMb != kCachePoolAuto)
    checkField("propagation.cache_pool_mb", p.cachePoolMb, origin);
  checkField("propagation.frame_rate", p.frameRate, origin);
  checkField("propagation.ir_length", p.irLength, origin);
  // The temperature before the speed of sound, which is derived from it when not given: a
  // wild temperature is named, not the speed the caller never set.
  checkField("propagation.temperature", p.temperatureC, origin);
  checkField("propagation.humidity", p.humidityPercent, origin);
  checkField("propagation.speed_of_sound", p.speedOfSound, origin);
}

// Key times in order and every keyframe's position within the coordinate limit.
void checkTrajectory(const std::vector<Keyframe>& keys, const Origin& origin,
                     const std::string& f) {
  checkKeyTimes(keys, origin, f);
  for (size_t k = 0; k < keys.size(); ++k)
    checkPosition(keys[k].position, origin, at(f, k) + ".position");
}

void checkSources(const std::vector<SourceDesc>& sources, const Origin& origin) {
  checkCount("sources", sources.size(), origin);
  checkNames(sources, "sources", "source", origin);
  for (size_t i = 0; i < sources.size(); ++i) {
    const SourceDesc& s = sources[i];
    const std::string f = at("sources", i);
    checkPosition(s.position, origin, f + ".position");
    checkField("sources[].gain_db", s.gainDb, origin, f + ".gain_db");
    checkTrajectory(s.trajectory, origin, f + ".trajectory");
    checkBands("sources[].directivity.a", s.directivity.a, origin, f + ".directivity.a");
    checkRotation(s.rotation, origin, f + ".rotation");
    for (size_t k = 0; k < s.trajectory.size(); ++k)
      if (s.trajectory[k].rotation)
        checkRotation(*s.trajectory[k].rotation, origin, at(f + ".trajectory", k) + ".rotation");
  }
}

void checkListenerKeys(const ListenerDesc& l, const Origin& origin, const std::string& f) {
  checkTrajectory(l.trajectory, origin, f + ".trajectory");
  for (size_t k = 0; k < l.trajectory.size(); ++k) {
    const Keyframe& key = l.trajectory[k];
    const std::string kf = at(f + ".trajectory", k);
    if (key.yawDegrees.has_value() != l.trajectory.front().yawDegrees.has_value())
      fail(origin, kf + ".yaw", "give \"yaw\" on every keyframe or on none");
    if (key.yawDegrees) checkField("listener.yaw", *key.yawDegrees, origin, kf + ".yaw");
    if (key.pitchDegrees) checkField("listener.pitch", *key.pitchDegrees, origin, kf + ".pitch");
    if (key.rollDegrees) checkField("listener.roll", *key.rollDegrees, origin, kf + ".roll");
  }
}

void checkListeners(const std::vector<ListenerDesc>& listeners, const Origin& origin) {
  checkCount("listeners", listeners.size(), origin);
  checkNames(listeners, "listeners", "listener", origin, true);
  for (size_t i = 0; i < listeners.size(); ++i) {
    const ListenerDesc& l = listeners[i];
    const std::string f = at("listeners", i);
    checkPosition(l.position, origin, f + ".position");
    checkField("listener.radius", l.radius, origin, f + ".radius");
    checkField("listener.yaw", l.yawDegrees, origin, f + ".yaw");
    checkField("listener.pitch", l.pitchDegrees, origin, f + ".pitch");
    checkField("listener.roll", l.rollDegrees, origin, f + ".roll");
    checkListenerKeys(l, origin, f);
  }
}

void checkObjects(const std::vector<ObjectDesc>& objects, const Origin& origin) {
  checkCount("objects", objects.size(), origin);
  checkNames(objects, "objects", "object", origin);
  for (size_t i = 0; i < objects.size(); ++i) {
    const ObjectDesc& o = objects[i];
    const std::string f = at("objects", i) + ".trajectory";
    if (o.trajectory.empty()) fail(origin, f, "at least one keyframe is required");
    checkKeyTimes(o.trajectory, origin, f);
    for (size_t k = 0; k < o.trajectory.size(); ++k)
      checkPosition(o.trajectory[k].position, origin, at(f, k) + ".position");
  }
}

/// Indices in range and coordinates within limits. `path`: "mesh" or "objects[i].mesh".
void checkMesh(const Mesh& mesh, size_t materials, const Origin& origin, const std::string& path) {
  if (mesh.triangles.empty()) fail(origin, path, "no triangles; nothing to trace");
  if (mesh.materialIndex.size() != mesh.triangles.size())
    fail(origin, path + ".materials", "one material index per triangle is required");
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    checkPosition(mesh.vertices[v], origin, at(path + ".vertices", v));
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (size_t k = 0; k < 3; ++k)
      if (mesh.triangles[t][k] >= mesh.vertices.size())
        fail(origin, at(at(path + ".triangles", t), k),
             std::to_string(mesh.triangles[t][k]) + " >= vertex count " +
                 std::to_string(mesh.vertices.size()));
    if (mesh.materialIndex[t] >= materials)
      fail(origin, at(path + ".materials", t),
           std::to_string(mesh.materialIndex[t]) + " >= material count " +
               std::to_string(materials));
  }
}

}  // namespace

void checkName(const std::string& name, bool namesFile, const Origin& origin,
               const std::string& field) {
  if (name.empty()) fail(origin, field, "must not be empty");
  for (const char c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      fail(origin, field, "must not contain control characters");
  if (namesFile && name.find('/') != std::string::npos)
    fail(origin, field, "must not contain '/' (it becomes part of output file names)");
}

std::string Origin::fieldName(const std::string& path) const {
  return spell ? spell(path) : path;
}

Origin commandLineOrigin() {
  return Origin{"command line", [](const std::string& path) -> std::string {
                  static const std::pair<const char*, const char*> kFlags[] = {
                      {"propagation.rays_per_frame", "--rays"},
                      {"propagation.max_order", "--max-order"},
                      {"propagation.cache_tau", "--tau"},
                      {"propagation.cache_memory_mb", "--cache-memory-mb"},
                      {"propagation.cache_pool_mb", "--cache-pool-mb"},
                      {"propagation.frame_rate", "--frame-rate"},
                      {"audio.block_size", "--block-size"},
                      {"audio.ambisonic_order", "--ambisonic-order"},
                      {"audio.late_buses", "--late-buses"},
                      {"audio.cluster_angle", "--cluster-angle"}};
                  for (const auto& [key, flag] : kFlags)
                    if (path == key) return flag;
                  return path;
                }};
}

void checkCount(const char* field, size_t count, const Origin& origin) {
  const Limit& l = limitOf(field);
  const std::string n = std::to_string(count) + " " + field;
  if (double(count) > l.max)
    fail(origin, field, n + ", more than the limit of " + valueText(l.max));
  if (double(count) < l.min)
    fail(origin, field, n + ", fewer than the minimum of " + valueText(l.min));
}

void checkField(std::string_view field, double value, const Origin& origin,
                const std::string& path) {
  const Limit& l = limitOf(field);
  if (withinLimit(l, value)) return;
  char why[160];
  writeLimitProblem(l, value, why, sizeof why);
  fail(origin, path.empty() ? std::string(field) : path, why);
}

float checkFloatField(std::string_view field, double written, const Origin& origin,
                      const std::string& path, const std::string& writtenText) {
  checkField(field, written, origin, path);
  char given[64];
  std::snprintf(given, sizeof given, "%g", written);
  const std::string as = writtenText.empty() ? std::string(given) : writtenText;
  const std::string where = path.empty() ? std::string(field) : path;
  // Checked before the conversion, which is undefined for a finite value beyond the range.
  if (std::abs(written) > double(std::numeric_limits<float>::max()))
    fail(origin, where, as + " is beyond single precision (at most 3.4e38 in magnitude)");
  const Limit& l = limitOf(field);
  const float held = float(written) + 0.f;  // + 0: -0 held as 0
  const bool underflow = written != 0.0 && held == 0.f;
  if (withinLimit(l, double(held)) && !underflow) return held;
  std::string why = as + " rounds to " + valueText(double(held)) + " in single precision";
  if (!withinLimit(l, double(held))) {
    char problem[160];
    writeLimitProblem(l, double(held), problem, sizeof problem);
    why += std::string(": ") + problem;
  }
  fail(origin, where, why);
}

/// The wave band's fields, its crossover below its maximum frequency and its grid fine enough
/// for it (c: the speed of sound, m/s).
static void checkWave(const WaveSettings& w, double c, const Origin& origin) {
  checkField("wave.max_frequency", w.maxFrequencyHz, origin);
  checkField("wave.crossover_hz", w.crossoverHz, origin);
  checkField("wave.grid_spacing", w.gridSpacingM, origin);
  if (!(w.crossover() < w.maxFrequencyHz))
    fail(origin, "wave.crossover_hz",
         valueText(w.crossover()) + " Hz must lie below wave.max_frequency (" +
             valueText(w.maxFrequencyHz) + " Hz)");
  if (w.gridSpacingM > 0.f && double(w.gridSpacingM) > w.maxSpacing(c) * (1.0 + 1e-6))
    fail(origin, "wave.grid_spacing",
         valueText(w.gridSpacingM) + " m is too coarse for wave.max_frequency " +
             valueText(w.maxFrequencyHz) + " Hz (at most " + valueText(float(w.maxSpacing(c))) +
             " m: " + valueText(kWavePointsPerWavelength) + " nodes per wavelength)");
}

void validate(const SceneDesc& scene, const Origin& origin) {
  checkMaterials(scene.materials, origin);
  checkPropagation(scene.propagation, origin);
  checkWave(scene.wave, scene.propagation.speedOfSound, origin);
  checkField("audio.sample_rate", scene.audio.sampleRate, origin);
  checkField("audio.block_size", scene.audio.blockSize, origin);
  checkField("audio.ambisonic_order", scene.audio.ambisonicOrder, origin);
  checkField("audio.late_buses", scene.audio.lateBuses, origin);
  checkField("audio.cluster_angle", scene.audio.clusterAngleDegrees, origin);
  checkSources(scene.sources, origin);
  checkListeners(scene.listeners, origin);
  checkObjects(scene.objects, origin);
  checkMesh(scene.mesh, scene.materials.size(), origin, "mesh");
  for (size_t i = 0; i < scene.objects.size(); ++i)
    checkMesh(scene.objects[i].mesh, scene.materials.size(), origin, at("objects", i) + ".mesh");
}

}  // namespace dpc
