#include "scene/model_animation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <iterator>
#include <nlohmann/json.hpp>

#include "common/input_error.h"
#include "scene/quaternion.h"

namespace dpc {
namespace {

using nlohmann::json;

/// A node's translation, rotation and scale as the glTF JSON gives them (defaults: none, identity,
/// one). Values assimp accepted, so only types are guarded.
Trs nodeTrs(const json& n) {
  auto numbers = [&](const char* key, size_t count) {
    std::vector<double> v;
    if (n.contains(key) && n[key].is_array() && n[key].size() == count)
      for (const json& x : n[key]) v.push_back(x.is_number() ? x.get<double>() : 0.0);
    return v;
  };
  Trs trs;
  if (const auto t = numbers("translation", 3); !t.empty())
    trs.position = glm::vec3(float(t[0]), float(t[1]), float(t[2]));
  if (const auto r = numbers("rotation", 4); !r.empty())
    trs.rotation = unitQuaternion(r[0], r[1], r[2], r[3]).value_or(trs.rotation);
  if (const auto s = numbers("scale", 3); !s.empty())
    trs.scale = glm::vec3(float(s[0]), float(s[1]), float(s[2]));
  return trs;
}

template <class Key>
double seconds(const Key& k, double ticksPerSecond) {
  return k.mTime / ticksPerSecond;
}

/// One path's keys as (seconds, value) with the STEP hold keys inserted.
template <class Value>
struct Track {
  std::vector<double> t;
  std::vector<Value> v;
};

[[noreturn]] void failKey(const std::string& file, const NodeChannel& c, const char* path, size_t k,
                          const std::string& problem) {
  throw InputError(file,
                   "animation \"" + c.animation + "\" node \"" +
                       std::string(c.channel->mNodeName.C_Str()) + "\" " + path + " key " +
                       std::to_string(k + 1),
                   problem);
}

template <class Value, class Key, class Convert>
Track<Value> readTrack(const std::string& file, const NodeChannel& c, const char* path,
                       const Key* keys, unsigned n, Convert convert) {
  std::string interpolation = "LINEAR";
  if (c.gltf) {
    const auto it = c.gltf->interpolation.find(path);
    if (it == c.gltf->interpolation.end()) return {};  // not animated: the rest value holds
    interpolation = it->second;
  }
  if (interpolation == "CUBICSPLINE")
    failKey(file, c, path, 0,
            "CUBICSPLINE interpolation is not supported (assimp 5.2 reads its tangents as keys); "
            "export LINEAR or STEP keys");
  Track<Value> track;
  for (unsigned k = 0; k < n; ++k) {
    const double t = seconds(keys[k], c.ticksPerSecond);
    if (!std::isfinite(t) || t < 0) failKey(file, c, path, k, "time is negative or not finite");
    if (k > 0 && !(t > track.t.back()))
      failKey(file, c, path, k, "time is not after the previous key's");
    const Value value = convert(keys[k].mValue, k);
    if (interpolation == "STEP" && k > 0 && t - kStepHoldSeconds > track.t.back()) {
      const Value held = track.v.back();
      track.t.push_back(t - kStepHoldSeconds);
      track.v.push_back(held);
    }
    track.t.push_back(t);
    track.v.push_back(value);
  }
  return track;
}

glm::vec3 mix(const glm::vec3& a, const glm::vec3& b, float u) {
  return a + (b - a) * u;
}
glm::quat mix(const glm::quat& a, const glm::quat& b, float u) {
  return glm::normalize(glm::slerp(a, b, u));  // glm::slerp takes the shorter arc
}

/// The track at time t: a key's own value at its time, interpolated between keys, clamped.
template <class Value>
Value sample(const Track<Value>& track, double t) {
  const auto hi = std::lower_bound(track.t.begin(), track.t.end(), t);
  if (hi == track.t.end()) return track.v.back();
  const size_t i = size_t(hi - track.t.begin());
  if (*hi == t || i == 0) return track.v[i];
  const double u = (t - track.t[i - 1]) / (track.t[i] - track.t[i - 1]);
  return mix(track.v[i - 1], track.v[i], float(u));
}

glm::vec3 finiteVector(const std::string& file, const NodeChannel& c, const char* path,
                       const aiVector3D& v, size_t k) {
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    failKey(file, c, path, k, "value is NaN or infinite");
  return glm::vec3(v.x, v.y, v.z);
}

}  // namespace

std::map<std::string, GltfNode> readGltfNodes(const json& doc) {
  std::map<std::string, GltfNode> out;
  if (!doc.is_object() || !doc.contains("nodes") || !doc["nodes"].is_array()) return out;
  const json& nodes = doc["nodes"];
  for (const json& n : nodes)
    if (n.is_object() && !n.contains("matrix")) out[n.value("name", "")].trs = nodeTrs(n);
  if (!doc.contains("animations") || !doc["animations"].is_array()) return out;
  for (const json& a : doc["animations"]) {
    if (!a.is_object() || !a.contains("channels") || !a.contains("samplers")) continue;
    for (const json& ch : a["channels"]) {
      const size_t node = ch.value("/target/node"_json_pointer, size_t(0));
      const size_t sampler = ch.value("sampler", size_t(0));
      if (node >= nodes.size() || sampler >= a["samplers"].size()) continue;
      out[nodes[node].value("name", "")].interpolation[ch.value("/target/path"_json_pointer, "")] =
          a["samplers"][sampler].value("interpolation", "LINEAR");
    }
  }
  return out;
}

NodeKeys readNodeKeys(const NodeChannel& c, const std::string& file) {
  const aiNodeAnim& a = *c.channel;
  const auto position = readTrack<glm::vec3>(
      file, c, "translation", a.mPositionKeys, a.mNumPositionKeys,
      [&](const aiVector3D& v, size_t k) { return finiteVector(file, c, "translation", v, k); });
  const auto rotation =
      readTrack<glm::quat>(file, c, "rotation", a.mRotationKeys, a.mNumRotationKeys,
                           [&](const aiQuaternion& q, size_t k) {
                             const auto unit = unitQuaternion(q.x, q.y, q.z, q.w);
                             if (!unit)
                               failKey(file, c, "rotation", k, "has zero length or is not finite");
                             return *unit;
                           });
  const auto scale = readTrack<glm::vec3>(
      file, c, "scale", a.mScalingKeys, a.mNumScalingKeys,
      [&](const aiVector3D& v, size_t k) { return finiteVector(file, c, "scale", v, k); });
  NodeKeys out;
  out.scale = scale.v.empty() ? c.restScale : scale.v.front();
  for (size_t k = 1; k < scale.v.size(); ++k)
    if (scale.v[k] != out.scale)
      failKey(file, c, "scale", k, "differs from the first: objects are rigid (no animated scale)");
  std::vector<double> times = position.t;
  if (times.empty() && rotation.t.empty()) times.push_back(0.0);  // a scale-only channel
  times.insert(times.end(), rotation.t.begin(), rotation.t.end());
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  for (double t : times) {
    ObjectKeyframe key = c.rest;
    key.timeSeconds = t;
    if (!position.t.empty()) key.position = sample(position, t);
    if (!rotation.t.empty()) key.rotation = sample(rotation, t);
    out.keys.push_back(key);
  }
  return out;
}

}  // namespace dpc
