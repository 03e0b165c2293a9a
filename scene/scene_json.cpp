// Scene file reader: the JSON's sections into a SceneDesc, then the meshes (scene/obj_reader.h,
// scene/mesh_builder.h), then the one validation (scene/validate.h). The key-by-key format is
// docs/scene-format.md; every numeric range comes from scene/limits.h and is checked as each
// value is read, so the first error named is the first in the file.
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "common/air_absorption.h"
#include "common/input_error.h"
#include "scene/enum_names.h"
#include "scene/json_reader.h"
#include "scene/limits.h"
#include "scene/material_json.h"
#include "scene/mesh_builder.h"
#include "scene/model_reader.h"
#include "scene/obj_reader.h"
#include "scene/quaternion.h"
#include "scene/scene.h"
#include "scene/validate.h"

namespace dpc {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

/// Materials sorted by name (nlohmann::json objects iterate in key order).
void readMaterials(const JsonReader& r, const json& root, SceneDesc& scene) {
  const json& mats = r.require(root, "", "materials");
  r.expectObject(mats, "materials");
  for (const auto& [name, value] : mats.items()) {
    if (!name.empty() && name[0] == '_') continue;
    if (name.empty()) r.fail("materials", "a material name must not be empty");
    scene.materials.push_back(readSceneMaterial(r, value, name, "materials." + name));
  }
  if (scene.materials.empty()) r.fail("materials", "at least one material is required");
}

/// Reads a keyframe time at kf + ".t": finite, >= 0, greater than `previous` (if any).
double keyTime(const JsonReader& r, const json& k, const std::string& kf,
               const std::optional<double>& previous) {
  const double t = r.number(r.require(k, kf, "t"), join(kf, "t"));
  if (t < 0.0) r.fail(join(kf, "t"), k["t"].dump() + " must be >= 0");
  if (previous && !(t > *previous))
    r.fail(join(kf, "t"), k["t"].dump() + " is not greater than the previous keyframe's t (" +
                              valueText(*previous) + "); times must be strictly increasing");
  return t;
}

template <class Keys>
std::optional<double> lastTime(const Keys& keys) {
  return keys.empty() ? std::nullopt : std::optional(keys.back().timeSeconds);
}

/// [x, y, z, w] (glTF order) of non-zero length, normalised.
glm::quat readQuaternion(const JsonReader& r, const json& v, const std::string& field) {
  if (!v.is_array() || v.size() != 4)
    r.fail(field, "expected a unit quaternion [x, y, z, w], got " + JsonReader::describe(v));
  float c[4];
  for (int i = 0; i < 4; ++i) c[i] = r.floatNumber(v[size_t(i)], index(field, size_t(i)));
  // Not exactly unit (rounded decimals in a file): normalised rather than refused.
  const auto q = unitQuaternion(c[0], c[1], c[2], c[3]);
  if (!q) r.fail(field, v.dump() + " has zero length; a rotation needs a unit quaternion");
  return *q;
}

/// A source's keyframes {t, position, rotation?}; a rotation on every keyframe or on none.
std::vector<Keyframe> readPositionKeys(const JsonReader& r, const json& t, const std::string& tf) {
  if (!t.is_array() || t.empty())
    r.fail(tf, "expected a non-empty array of {\"t\", \"position\"} keyframes, got " +
                   JsonReader::describe(t));
  std::vector<Keyframe> keys;
  for (size_t i = 0; i < t.size(); ++i) {
    const std::string kf = index(tf, i);
    const json& k = t[i];
    r.expectObject(k, kf);
    r.checkKeys(k, kf, {"t", "position", "rotation", "teleport"});
    Keyframe key;
    key.timeSeconds = keyTime(r, k, kf, lastTime(keys));
    if (const json* x = JsonReader::find(k, "teleport"))
      key.teleport = r.boolean(*x, join(kf, "teleport"));
    key.position = r.vec3(r.require(k, kf, "position"), join(kf, "position"));
    if (const json* q = JsonReader::find(k, "rotation"))
      key.rotation = readQuaternion(r, *q, join(kf, "rotation"));
    if (!keys.empty() && keys.front().rotation.has_value() != key.rotation.has_value())
      r.fail(join(kf, "rotation"), "give \"rotation\" on every keyframe or on none");
    keys.push_back(key);
  }
  return keys;
}

/// "directivity": a pattern name, {"pattern": NAME} or {"a": one number or 8 numbers in [0, 1]}.
Directivity readDirectivity(const JsonReader& r, const json& v, const std::string& field) {
  auto named = [&](const json& name, const std::string& f) {
    const std::string s = r.string(name, f);
    const auto a = directivityPatternA(s);
    if (!a)
      r.fail(f, inQuotes(s) +
                    " is not one of \"omni\", \"subcardioid\", \"cardioid\", "
                    "\"supercardioid\", \"hypercardioid\", \"figure8\"");
    return Directivity{Bands(*a)};
  };
  if (v.is_string()) return named(v, field);
  if (!v.is_object())
    r.fail(field, "expected a pattern name or an object with \"pattern\" or \"a\", got " +
                      JsonReader::describe(v));
  r.checkKeys(v, field, {"pattern", "a"});
  const json* p = JsonReader::find(v, "pattern");
  const json* a = JsonReader::find(v, "a");
  if ((p == nullptr) == (a == nullptr)) r.fail(field, "give exactly one of \"pattern\" and \"a\"");
  if (p) return named(*p, join(field, "pattern"));
  return Directivity{readBands(r, *a, join(field, "a"), "sources[].directivity.a")};
}

/// The "position" key of v, or else the trajectory's first keyframe; one of them is required.
glm::vec3 readStartPosition(const JsonReader& r, const json& v, const std::string& field,
                            const std::vector<Keyframe>& trajectory) {
  if (const json* p = JsonReader::find(v, "position")) return r.vec3(*p, join(field, "position"));
  if (trajectory.empty())
    r.fail(join(field, "position"), "missing required key (needed when there is no trajectory)");
  return trajectory.front().position;
}

std::vector<ObjectKeyframe> readObjectKeys(const JsonReader& r, const json& t,
                                           const std::string& tf) {
  if (!t.is_array() || t.empty())
    r.fail(tf,
           "expected a non-empty array of {\"t\", \"position\", \"rotation\"?} keyframes, got " +
               JsonReader::describe(t));
  std::vector<ObjectKeyframe> keys;
  for (size_t k = 0; k < t.size(); ++k) {
    const std::string kf = index(tf, k);
    const json& kv = t[k];
    r.expectObject(kv, kf);
    r.checkKeys(kv, kf, {"t", "position", "rotation"});
    ObjectKeyframe key;
    key.timeSeconds = keyTime(r, kv, kf, lastTime(keys));
    key.position = r.vec3(r.require(kv, kf, "position"), join(kf, "position"));
    if (const json* q = JsonReader::find(kv, "rotation"))
      key.rotation = readQuaternion(r, *q, join(kf, "rotation"));
    keys.push_back(key);
  }
  return keys;
}

/// A name: a non-empty string, unique among `others`' names (`what`: "source", "object").
template <class Items>
std::string readName(const JsonReader& r, const json& v, const std::string& f, const Items& others,
                     const char* what) {
  std::string name = r.string(r.require(v, f, "name"), join(f, "name"));
  if (name.empty()) r.fail(join(f, "name"), "must not be empty");
  for (const auto& other : others)
    if (other.name == name)
      r.fail(join(f, "name"), std::string("duplicate ") + what + " name " + inQuotes(name));
  return name;
}

void readObjects(const JsonReader& r, const json& v, const fs::path& folder, SceneDesc& scene) {
  const std::string field = "objects";
  if (!v.is_array()) r.fail(field, "expected an array of objects, got " + JsonReader::describe(v));
  checkCount("objects", v.size(), Origin{r.file(), {}});
  for (size_t i = 0; i < v.size(); ++i) {
    const std::string f = index(field, i);
    const json& o = v[i];
    r.expectObject(o, f);
    r.checkKeys(o, f, {"name", "mesh", "trajectory", "loop"});
    ObjectDesc obj;
    obj.name = readName(r, o, f, scene.objects, "object");
    // Without "mesh", the object is the level's node of that name (checked with the meshes).
    if (const json* m = JsonReader::find(o, "mesh"))
      obj.meshPath = resolve(folder, r.string(*m, join(f, "mesh"))).string();
    if (const json* t = JsonReader::find(o, "trajectory"))
      obj.trajectory = readObjectKeys(r, *t, join(f, "trajectory"));
    else if (!obj.meshPath.empty())
      r.fail(join(f, "trajectory"), "missing required key (only a level's node may omit it)");
    if (const json* l = JsonReader::find(o, "loop")) obj.loop = r.boolean(*l, join(f, "loop"));
    scene.objects.push_back(std::move(obj));
  }
}

/// An existing file named by a string at `field`, resolved against the scene's folder.
std::string existingFile(const JsonReader& r, const json& v, const std::string& field,
                         const fs::path& folder) {
  const fs::path resolved = resolve(folder, r.string(v, field));
  std::error_code ec;
  if (!fs::exists(resolved, ec))
    r.fail(field, "file " + inQuotes(resolved.string()) + " not found");
  if (fs::is_directory(resolved, ec))
    r.fail(field, inQuotes(resolved.string()) + " is a directory, not a file");
  if (!fs::is_regular_file(resolved, ec))
    r.fail(field, inQuotes(resolved.string()) + " is not a regular file (FIFO, device or socket)");
  return resolved.string();
}

SourceDesc readSource(const JsonReader& r, const json& s, const std::string& f,
                      const fs::path& folder, const std::vector<SourceDesc>& others) {
  r.expectObject(s, f);
  r.checkKeys(s, f,
              {"name", "position", "signal", "gain_db", "loop", "trajectory", "trajectory_loop",
               "directivity", "rotation"});
  SourceDesc src;
  src.name = readName(r, s, f, others, "source");
  if (const json* t = JsonReader::find(s, "trajectory"))
    src.trajectory = readPositionKeys(r, *t, join(f, "trajectory"));
  src.position = readStartPosition(r, s, f, src.trajectory);
  if (const json* l = JsonReader::find(s, "trajectory_loop"))
    src.trajectoryLoop = r.boolean(*l, join(f, "trajectory_loop"));
  // No signal: the source's dry input comes from a host (C API, plugin) or is silent.
  if (const json* sig = JsonReader::find(s, "signal"))
    src.signalPath = existingFile(r, *sig, join(f, "signal"), folder);
  if (const json* g = JsonReader::find(s, "gain_db"))
    src.gainDb = float(r.limited(*g, join(f, "gain_db"), "sources[].gain_db"));
  if (const json* l = JsonReader::find(s, "loop")) src.loop = r.boolean(*l, join(f, "loop"));
  if (const json* d = JsonReader::find(s, "directivity"))
    src.directivity = readDirectivity(r, *d, join(f, "directivity"));
  if (const json* q = JsonReader::find(s, "rotation"))
    src.rotation = readQuaternion(r, *q, join(f, "rotation"));
  return src;
}

void readSources(const JsonReader& r, const json& v, const fs::path& folder, SceneDesc& scene) {
  const std::string field = "sources";
  if (!v.is_array()) r.fail(field, "expected an array of sources, got " + JsonReader::describe(v));
  if (v.empty()) r.fail(field, "at least one source is required");
  checkCount("sources", v.size(), Origin{r.file(), {}});
  for (size_t i = 0; i < v.size(); ++i)
    scene.sources.push_back(readSource(r, v[i], index(field, i), folder, scene.sources));
}

Keyframe readListenerKey(const JsonReader& r, const json& k, const std::string& kf,
                         const std::vector<Keyframe>& before) {
  r.expectObject(k, kf);
  r.checkKeys(k, kf, {"t", "position", "yaw", "pitch", "roll", "teleport"});
  Keyframe key;
  key.timeSeconds = keyTime(r, k, kf, lastTime(before));
  if (const json* x = JsonReader::find(k, "teleport"))
    key.teleport = r.boolean(*x, join(kf, "teleport"));
  key.position = r.vec3(r.require(k, kf, "position"), join(kf, "position"));
  if (const json* y = JsonReader::find(k, "yaw"))
    key.yawDegrees = float(r.limited(*y, join(kf, "yaw"), "listener.yaw"));
  if (const json* p = JsonReader::find(k, "pitch"))
    key.pitchDegrees = float(r.limited(*p, join(kf, "pitch"), "listener.pitch"));
  if (const json* q = JsonReader::find(k, "roll"))
    key.rollDegrees = float(r.limited(*q, join(kf, "roll"), "listener.roll"));
  if (!before.empty() && before.front().yawDegrees.has_value() != key.yawDegrees.has_value())
    r.fail(join(kf, "yaw"), "give \"yaw\" on every keyframe or on none");
  return key;
}

void readListener(const JsonReader& r, const json& v, const std::string& field, bool named,
                  ListenerDesc& listener) {
  r.expectObject(v, field);
  if (named) {
    r.checkKeys(v, field,
                {"name", "position", "radius", "trajectory", "loop", "yaw", "pitch", "roll"});
    listener.name = r.string(r.require(v, field, "name"), join(field, "name"));
    if (listener.name.empty()) r.fail(join(field, "name"), "must not be empty");
  } else {
    r.checkKeys(v, field, {"position", "radius", "trajectory", "loop", "yaw", "pitch", "roll"});
  }
  if (const json* t = JsonReader::find(v, "trajectory")) {
    const std::string tf = join(field, "trajectory");
    if (!t->is_array())
      r.fail(tf, "expected an array of {\"t\", \"position\"} keyframes, got " +
                     JsonReader::describe(*t));
    for (size_t i = 0; i < t->size(); ++i)
      listener.trajectory.push_back(readListenerKey(r, (*t)[i], index(tf, i), listener.trajectory));
  }
  listener.position = readStartPosition(r, v, field, listener.trajectory);
  if (const json* rad = JsonReader::find(v, "radius"))
    listener.radius = float(r.limited(*rad, join(field, "radius"), "listener.radius"));
  if (const json* l = JsonReader::find(v, "loop"))
    listener.loop = r.boolean(*l, join(field, "loop"));
  if (const json* y = JsonReader::find(v, "yaw"))
    listener.yawDegrees = float(r.limited(*y, join(field, "yaw"), "listener.yaw"));
  if (const json* p = JsonReader::find(v, "pitch"))
    listener.pitchDegrees = float(r.limited(*p, join(field, "pitch"), "listener.pitch"));
  if (const json* q = JsonReader::find(v, "roll"))
    listener.rollDegrees = float(r.limited(*q, join(field, "roll"), "listener.roll"));
}

/// `listener` (one, named "listener") or `listeners` (an array of named ones).
void readListeners(const JsonReader& r, const json& root, SceneDesc& scene) {
  const json* one = JsonReader::find(root, "listener");
  const json* many = JsonReader::find(root, "listeners");
  if (one && many) r.fail("listeners", "give either \"listener\" or \"listeners\", not both");
  if (!one && !many) r.fail("listener", "missing required key (or give \"listeners\")");
  if (one) {
    scene.listeners.emplace_back();
    readListener(r, *one, "listener", false, scene.listeners.back());
    return;
  }
  if (!many->is_array() || many->empty())
    r.fail("listeners",
           "expected a non-empty array of listeners, got " + JsonReader::describe(*many));
  checkCount("listeners", many->size(), Origin{r.file(), {}});
  for (size_t i = 0; i < many->size(); ++i) {
    ListenerDesc l;
    readListener(r, (*many)[i], index("listeners", i), true, l);
    for (const ListenerDesc& other : scene.listeners)
      if (other.name == l.name)
        r.fail(index("listeners", i) + ".name", "duplicate listener name " + inQuotes(l.name));
    scene.listeners.push_back(std::move(l));
  }
}

/// A string key naming one of an enum's values (`parse` returns nullopt for others).
template <class Parse>
auto readChoice(const JsonReader& r, const json& v, const std::string& field, Parse parse,
                const char* allowed) {
  const std::string s = r.string(v, field);
  const auto value = parse(s);
  if (!value) r.fail(field, inQuotes(s) + " is not one of " + allowed);
  return *value;
}

void readPropagationNumbers(const JsonReader& r, const json& v, PropagationSettings& p) {
  auto read = [&](const char* key, auto& out) {
    const std::string field = join("propagation", key);
    if (const json* x = JsonReader::find(v, key))
      out = static_cast<std::remove_reference_t<decltype(out)>>(r.limited(*x, field, field));
  };
  read("rays_per_frame", p.raysPerFrame);
  read("max_order", p.maxOrder);
  read("exact_order", p.exactOrder);
  read("patch_size", p.patchSize);
  read("cache_tau", p.cacheTau);
  read("cache_memory_mb", p.cacheMemoryMb);
  // "auto" (or no value): sized by the scene (cachePoolMbFor, engine/workload.h).
  if (const json* x = JsonReader::find(v, "cache_pool_mb"); x && x->is_string()) {
    if (r.string(*x, "propagation.cache_pool_mb") != "auto")
      r.fail("propagation.cache_pool_mb", "must be a number of MB or \"auto\"");
    p.cachePoolMb = kCachePoolAuto;
  } else {
    read("cache_pool_mb", p.cachePoolMb);
  }
  read("frame_rate", p.frameRate);
  read("ir_length", p.irLength);
  read("temperature", p.temperatureC);
  read("humidity", p.humidityPercent);
  // Without it: ideal-gas dry air at the temperature.
  p.speedOfSound = float(speedOfSoundAt(p.temperatureC));
  read("speed_of_sound", p.speedOfSound);
  if (const json* x = JsonReader::find(v, "roulette_threshold_db")) {
    const double db =
        r.limited(*x, "propagation.roulette_threshold_db", "propagation.roulette_threshold_db");
    p.rouletteThreshold = float(std::pow(10.0, db / 10.0));
  }
}

void readPropagation(const JsonReader& r, const json& v, PropagationSettings& p) {
  const std::string field = "propagation";
  r.expectObject(v, field);
  r.checkKeys(v, field,
              {"rays_per_frame",
               "max_order",
               "exact_order",
               "patch_size",
               "cache_tau",
               "cache_memory_mb",
               "cache_pool_mb",
               "frame_rate",
               "ir_length",
               "seed",
               "estimator",
               "dpc_weighting",
               "speed_of_sound",
               "temperature",
               "humidity",
               "air_absorption",
               "diffraction",
               "reflection_scattering",
               "roulette_threshold_db",
               "tracing"});
  auto f = [&](const char* key) { return join(field, key); };
  readPropagationNumbers(r, v, p);
  if (const json* x = JsonReader::find(v, "seed")) {
    if (!x->is_number_unsigned() && !(x->is_number_integer() && x->get<int64_t>() >= 0))
      r.fail(f("seed"), "expected an unsigned integer, got " + JsonReader::describe(*x));
    p.seed = x->get<uint64_t>();
  }
  if (const json* x = JsonReader::find(v, "estimator"))
    p.estimator = readChoice(r, *x, f("estimator"), parseEstimator, "\"dpc\", \"path_tracing\"");
  if (const json* x = JsonReader::find(v, "tracing"))
    p.tracing = readChoice(r, *x, f("tracing"), parseTracing,
                           "\"auto\", \"from_sources\", \"from_listeners\"");
  if (const json* x = JsonReader::find(v, "dpc_weighting"))
    p.dpcWeighting =
        readChoice(r, *x, f("dpc_weighting"), parseDpcWeighting, "\"ema\", \"seed\", \"window\"");
  if (const json* x = JsonReader::find(v, "air_absorption"))
    p.airAbsorption = r.boolean(*x, f("air_absorption"));
  if (const json* x = JsonReader::find(v, "diffraction"))
    p.diffraction = r.boolean(*x, f("diffraction"));
  if (const json* x = JsonReader::find(v, "reflection_scattering"))
    p.reflectionScattering = r.boolean(*x, f("reflection_scattering"));
}

void readAudio(const JsonReader& r, const json& v, const fs::path& folder, AudioSettings& a) {
  const std::string field = "audio";
  r.expectObject(v, field);
  r.checkKeys(v, field,
              {"sample_rate", "block_size", "output", "hrtf", "ambisonic_order", "max_re",
               "binaural_decoder", "rendering", "late_buses", "cluster_angle"});
  if (const json* x = JsonReader::find(v, "output"))
    a.output = readChoice(r, *x, join(field, "output"), parseOutputFormat,
                          "\"mono\", \"stereo\", \"binaural\", \"ambisonics\", "
                          "\"ambisonic_binaural\"");
  if (const json* x = JsonReader::find(v, "hrtf"))
    a.hrtfPath = existingFile(r, *x, join(field, "hrtf"), folder);
  if (const json* x = JsonReader::find(v, "sample_rate"))
    a.sampleRate = int(r.limited(*x, "audio.sample_rate", "audio.sample_rate"));
  if (const json* x = JsonReader::find(v, "block_size"))
    a.blockSize = int(r.limited(*x, "audio.block_size", "audio.block_size"));
  if (const json* x = JsonReader::find(v, "ambisonic_order"))
    a.ambisonicOrder = int(r.limited(*x, "audio.ambisonic_order", "audio.ambisonic_order"));
  if (const json* x = JsonReader::find(v, "max_re")) a.maxRe = r.boolean(*x, join(field, "max_re"));
  if (const json* x = JsonReader::find(v, "binaural_decoder"))
    a.binauralDecoder = readChoice(r, *x, join(field, "binaural_decoder"), parseBinauralDecoder,
                                   "\"magls\", \"sampling\"");
  if (const json* x = JsonReader::find(v, "rendering"))
    a.rendering = readChoice(r, *x, join(field, "rendering"), parseRendering,
                             "\"auto\", \"per_source\", \"hybrid\"");
  if (const json* x = JsonReader::find(v, "late_buses"))
    a.lateBuses = int(r.limited(*x, "audio.late_buses", "audio.late_buses"));
  if (const json* x = JsonReader::find(v, "cluster_angle"))
    a.clusterAngleDegrees = float(r.limited(*x, "audio.cluster_angle", "audio.cluster_angle"));
}

Mesh buildSceneMesh(const SceneDesc& scene, const RawMesh& raw,
                    std::vector<std::string>& warnings) {
  return buildMesh(raw, materialIndicesByName(raw, scene.materials, scene.path), warnings);
}

/// Reads and builds one mesh file (OBJ, or every triangle of a glTF/FBX model in its world
/// frame); meshField names the scene key ("mesh", "objects[1].mesh").
Mesh loadMesh(const SceneDesc& scene, const std::string& file, const std::string& meshField,
              std::vector<std::string>& warnings) {
  if (isModelFile(file))
    return buildSceneMesh(scene, readModel(scene.path, file, meshField, {}).world, warnings);
  return buildSceneMesh(scene, readObj(scene.path, file, meshField), warnings);
}

/// The scene's mesh. A glTF/FBX level also gives the objects without a "mesh" of their own:
/// the nodes of their names, with the file's animation unless the scene gives keyframes.
void loadLevel(const JsonReader& r, SceneDesc& scene) {
  std::vector<ModelObjectRequest> requests;
  std::vector<size_t> requestObject;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    if (!scene.objects[i].meshPath.empty()) continue;
    if (!isModelFile(scene.meshPath))
      r.fail(index("objects", i) + ".mesh",
             "missing required key (only a glTF or FBX level's nodes may omit it)");
    requests.push_back({scene.objects[i].name, index("objects", i) + ".name"});
    requestObject.push_back(i);
  }
  if (!isModelFile(scene.meshPath)) {
    scene.mesh = loadMesh(scene, scene.meshPath, "mesh", scene.warnings);
    return;
  }
  RawModel model = readModel(scene.path, scene.meshPath, "mesh", requests);
  scene.mesh = buildSceneMesh(scene, model.world, scene.warnings);
  for (size_t k = 0; k < requests.size(); ++k) {
    ObjectDesc& o = scene.objects[requestObject[k]];
    o.meshPath = scene.meshPath;
    o.mesh = buildSceneMesh(scene, model.objects[k].mesh, scene.warnings);
    if (o.trajectory.empty()) o.trajectory = std::move(model.objects[k].trajectory);
  }
}

/// The meshes, last: the most expensive step, after the cheap checks. Warns about materials
/// that no triangle uses.
void loadMeshes(const JsonReader& r, const json& root, SceneDesc& scene) {
  const fs::path folder = fs::path(scene.path).parent_path();
  scene.meshPath = resolve(folder, r.string(r.require(root, "", "mesh"), "mesh")).string();
  loadLevel(r, scene);
  for (size_t i = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].mesh.triangles.empty())
      scene.objects[i].mesh =
          loadMesh(scene, scene.objects[i].meshPath, index("objects", i) + ".mesh", scene.warnings);
  std::vector<bool> used(scene.materials.size(), false);
  for (uint32_t m : scene.mesh.materialIndex) used[m] = true;
  for (const ObjectDesc& o : scene.objects)
    for (uint32_t m : o.mesh.materialIndex) used[m] = true;
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (!used[i])
      scene.warnings.push_back(scene.path + ": materials." + scene.materials[i].name +
                               ": not used by any triangle of " + scene.meshPath +
                               (scene.objects.empty() ? "" : " or of an object"));
}

void readWave(const JsonReader& r, const json& v, WaveSettings& w) {
  const std::string field = "wave";
  r.expectObject(v, field);
  r.checkKeys(v, field, {"enabled", "max_frequency", "crossover_hz", "grid_spacing"});
  if (const json* x = JsonReader::find(v, "enabled")) w.enabled = r.boolean(*x, "wave.enabled");
  auto read = [&](const char* key, float& out) {
    const std::string f = join(field, key);
    if (const json* x = JsonReader::find(v, key)) out = float(r.limited(*x, f, f));
  };
  read("max_frequency", w.maxFrequencyHz);
  read("crossover_hz", w.crossoverHz);
  read("grid_spacing", w.gridSpacingM);
}

}  // namespace

SceneDesc loadScene(const std::string& path) {
  SceneDesc scene;
  scene.path = path;
  scene.propagation.speedOfSound = float(speedOfSoundAt(scene.propagation.temperatureC));
  const json root = parseJsonFile(path);
  const JsonReader r(path);
  if (!root.is_object())
    r.fail("", "expected a JSON object at the top level, got " + JsonReader::describe(root));
  r.checkKeys(
      root, "",
      {"mesh", "materials", "sources", "listener", "listeners", "objects", "propagation", "audio",
       "wave"});
  const fs::path folder = fs::path(path).parent_path();
  readMaterials(r, root, scene);
  readSources(r, r.require(root, "", "sources"), folder, scene);
  readListeners(r, root, scene);
  if (const json* o = JsonReader::find(root, "objects")) readObjects(r, *o, folder, scene);
  if (const json* p = JsonReader::find(root, "propagation")) {
    readPropagation(r, *p, scene.propagation);
    // The reflection-based scattering runs inside the edge diffraction's model: say so when a
    // scene asks for it with diffraction off, rather than ignore the key.
    if (JsonReader::find(*p, "reflection_scattering") && scene.propagation.reflectionScattering &&
        !scene.propagation.diffraction)
      scene.warnings.push_back(path + ": propagation.reflection_scattering: has no effect with "
                               "propagation.diffraction false");
  }
  if (const json* a = JsonReader::find(root, "audio")) readAudio(r, *a, folder, scene.audio);
  if (const json* w = JsonReader::find(root, "wave")) readWave(r, *w, scene.wave);
  loadMeshes(r, root, scene);
  validate(scene, Origin{path, {}});
  return scene;
}

}  // namespace dpc
