// The mesh and animation sections of the glTF level checks (scene/gltf_check.h).
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "scene/gltf_rules.h"

namespace dpc::gltf {
namespace {

using nlohmann::json;

constexpr const char* kModeNames[] = {"POINTS",    "LINES",          "LINE_LOOP",   "LINE_STRIP",
                                      "TRIANGLES", "TRIANGLE_STRIP", "TRIANGLE_FAN"};
constexpr uint64_t kTriangles = 4;

/// The primitive's mode: TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN.
uint64_t triangleMode(const Level& l, const json& p, const std::string& field,
                      const std::string& who) {
  const uint64_t mode = integerAt(l, p, field, "mode", 0, UINT32_MAX, kTriangles);
  const std::string f = join(field, "mode");
  if (mode > 6)
    l.r.fail(f, who + std::to_string(mode) +
                    " is not a glTF primitive mode (0 POINTS .. 6 "
                    "TRIANGLE_FAN)");
  if (mode < kTriangles)
    l.r.fail(f, who + std::to_string(mode) + " (" + kModeNames[mode] +
                    ") is not supported: dpc reflects sound off surfaces, so it reads triangles "
                    "only (4 TRIANGLES, 5 TRIANGLE_STRIP, 6 TRIANGLE_FAN)");
  return mode;
}

/// "" when `a` has a format glTF 2.0 allows for the vertex attribute `semantic`, else the
/// formats it allows. Application-specific ("_NAME") and unknown attributes take any format.
std::string attributeRule(const std::string& semantic, const Accessor& a) {
  const bool unitFloat = a.component->code == kFloat && !a.normalized;
  const bool unitInteger =
      a.normalized && (a.component->code == kUnsignedByte || a.component->code == kUnsignedShort);
  const std::string type = a.type->name;
  const char* orUnit = ", or of UNSIGNED_BYTE or UNSIGNED_SHORT normalized";
  if (semantic == "NORMAL") return a.is("VEC3", kFloat) ? "" : "a VEC3 of FLOAT";
  if (semantic == "TANGENT") return a.is("VEC4", kFloat) ? "" : "a VEC4 of FLOAT";
  if (semantic.starts_with("TEXCOORD_"))
    return type == "VEC2" && (unitFloat || unitInteger) ? ""
                                                        : "a VEC2 of FLOAT" + std::string(orUnit);
  if (semantic.starts_with("COLOR_"))
    return (type == "VEC3" || type == "VEC4") && (unitFloat || unitInteger)
               ? ""
               : "a VEC3 or VEC4 of FLOAT" + std::string(orUnit);
  if (semantic.starts_with("WEIGHTS_"))
    return type == "VEC4" && (unitFloat || unitInteger) ? ""
                                                        : "a VEC4 of FLOAT" + std::string(orUnit);
  if (semantic.starts_with("JOINTS_"))
    return a.is("VEC4", kUnsignedByte) || a.is("VEC4", kUnsignedShort)
               ? ""
               : "a VEC4 of UNSIGNED_BYTE or UNSIGNED_SHORT";
  return "";
}

/// POSITION: a VEC3 of FLOAT with bounds. Integer positions (KHR_mesh_quantization) are
/// refused: assimp 5.2 copies their bytes into floats.
void checkPositions(const Level& l, const Accessor& a, const std::string& field,
                    const std::string& who) {
  if (!a.is("VEC3", kFloat))
    l.r.fail(field, who + "POSITION is " + a.format() +
                        "; dpc reads positions as a VEC3 of FLOAT (quantized positions, "
                        "KHR_mesh_quantization, are not supported)");
  if (!a.bounds) l.r.fail(field, who + "POSITION has no min and max, which glTF 2.0 requires");
}

/// The attributes (POSITION required; all of one count); returns the vertex count.
uint64_t checkAttributes(const Level& l, const json& p, const std::string& field,
                         const std::string& who) {
  const std::string f = join(field, "attributes");
  const json& attributes = l.r.require(p, field, "attributes");
  l.r.expectObject(attributes, f);
  if (!attributes.contains("POSITION"))
    l.r.fail(join(f, "POSITION"), who + "missing: a primitive without positions has no surface");
  const size_t position =
      requiredIndex(l, attributes, f, "POSITION", l.accessors.size(), "accessors", who);
  const uint64_t count = l.accessors[position].count;
  for (auto it = attributes.begin(); it != attributes.end(); ++it) {
    const std::string semantic = it.key(), af = join(f, semantic);
    const Accessor& a =
        l.accessors[indexValue(l, it.value(), af, l.accessors.size(), "accessors", who)];
    if (semantic == "POSITION") checkPositions(l, a, af, who);
    if (const std::string rule = attributeRule(semantic, a); !rule.empty())
      l.r.fail(af, who + semantic + " is " + a.format() + "; glTF 2.0 takes " + rule);
    if (a.count != count)
      l.r.fail(af, who + std::to_string(a.count) + " elements, POSITION " + std::to_string(count) +
                       "; every attribute has one per vertex");
  }
  return count;
}

/// The indices: a SCALAR of an unsigned integer type, tightly packed; returns their count.
uint64_t checkIndices(const Level& l, size_t i, const std::string& field, const std::string& who) {
  const Accessor& a = l.accessors[i];
  if (!a.is("SCALAR", kUnsignedByte) && !a.is("SCALAR", kUnsignedShort) &&
      !a.is("SCALAR", kUnsignedInt))
    l.r.fail(field, who + "indices are " + a.format() +
                        "; glTF 2.0 takes a SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or "
                        "UNSIGNED_INT");
  if (l.views[a.view].stride != 0)
    l.r.fail(field, who + "the indices' bufferView has a byteStride; indices are tightly packed");
  return a.count;
}

/// A primitive; returns its triangle count.
uint64_t checkPrimitive(const Level& l, const json& p, const std::string& field,
                        const std::string& who) {
  if (const json* ext = JsonReader::find(p, "extensions");
      ext && ext->is_object() && ext->contains("KHR_draco_mesh_compression"))
    l.r.fail(join(field, "extensions.KHR_draco_mesh_compression"),
             who + "Draco-compressed meshes are not supported (export without compression)");
  const uint64_t mode = triangleMode(l, p, field, who);
  if (!arrayAt(l, p, field, "targets").empty())
    l.r.fail(join(field, "targets"), who +
                                         "morph targets are not supported (they change the "
                                         "geometry; dpc needs it rigid)");
  (void)indexAt(l, p, field, "material", arrayAt(l, l.json.doc, "", "materials").size(),
                "materials", who);
  uint64_t n = checkAttributes(l, p, field, who);
  std::string countField = join(field, "attributes.POSITION");
  if (const auto i = indexAt(l, p, field, "indices", l.accessors.size(), "accessors", who)) {
    countField = join(field, "indices");
    n = checkIndices(l, *i, countField, who);
  }
  if (mode == kTriangles && (n < 3 || n % 3 != 0))
    l.r.fail(countField,
             who + std::to_string(n) + " vertices for TRIANGLES, which takes a multiple of 3");
  if (n < 3)
    l.r.fail(countField, who + std::to_string(n) + " vertices for " + kModeNames[mode] +
                             ", which takes at least 3");
  return mode == kTriangles ? n / 3 : n - 2;
}

/// One animation sampler as its channels need it.
struct Sampler {
  const Accessor* output = nullptr;
  std::string field;  ///< "animations[0].samplers[1]"
};

Sampler checkSampler(const Level& l, const json& s, const std::string& field,
                     const std::string& who) {
  const Accessor& input =
      l.accessors[requiredIndex(l, s, field, "input", l.accessors.size(), "accessors", who)];
  if (!input.is("SCALAR", kFloat))
    l.r.fail(join(field, "input"),
             who + "key times are " + input.format() + "; glTF 2.0 takes a SCALAR of FLOAT");
  if (!input.bounds)
    l.r.fail(join(field, "input"), who + "key times have no min and max, which glTF 2.0 requires");
  Sampler out{
      &l.accessors[requiredIndex(l, s, field, "output", l.accessors.size(), "accessors", who)],
      field};
  std::string interpolation = "LINEAR";
  if (const json* i = JsonReader::find(s, "interpolation"))
    interpolation = l.r.string(*i, join(field, "interpolation"));
  if (interpolation != "LINEAR" && interpolation != "STEP" && interpolation != "CUBICSPLINE")
    l.r.fail(
        join(field, "interpolation"),
        who + inQuotes(interpolation) + " is not a glTF interpolation (LINEAR, STEP, CUBICSPLINE)");
  const uint64_t perKey = interpolation == "CUBICSPLINE" ? 3 : 1;
  if (out.output->count != input.count * perKey)
    l.r.fail(join(field, "output"),
             who + std::to_string(out.output->count) + " values for " +
                 std::to_string(input.count) + " keys (its input); " + interpolation +
                 (perKey == 3 ? " takes three per key (in-tangent, value, out-tangent)"
                              : " takes one per key"));
  if (perKey == 3 && input.count < 2)
    l.r.fail(join(field, "input"), who + "CUBICSPLINE takes at least 2 keys");
  return out;
}

/// A channel: a node's translation, rotation or scale, once per animation, by a sampler whose
/// output holds FLOAT values of the path's type.
void checkChannel(const Level& l, const json& c, const std::string& field, const std::string& who,
                  const std::vector<Sampler>& samplers,
                  std::set<std::pair<size_t, std::string>>& targets) {
  const Sampler& s =
      samplers[requiredIndex(l, c, field, "sampler", samplers.size(), "samplers", who)];
  const std::string tf = join(field, "target");
  const json& target = l.r.require(c, field, "target");
  l.r.expectObject(target, tf);
  const auto node = indexAt(l, target, tf, "node", l.parent.size(), "nodes", who);
  if (!node) l.r.fail(join(tf, "node"), who + "missing: dpc reads only channels that move a node");
  const std::string path = l.r.string(l.r.require(target, tf, "path"), join(tf, "path"));
  if (path == "weights")
    l.r.fail(join(tf, "path"),
             who + "\"weights\" animates morph targets, which dpc does not support");
  if (path != "translation" && path != "rotation" && path != "scale")
    l.r.fail(join(tf, "path"), who + inQuotes(path) +
                                   " is not a glTF animation path "
                                   "(translation, rotation, scale, weights)");
  if (!targets.insert({*node, path}).second)
    l.r.fail(tf, who + "node " + std::to_string(*node) + "'s " + path +
                     " is the target of two channels");
  const char* type = path == "rotation" ? "VEC4" : "VEC3";
  if (!s.output->is(type, kFloat))
    l.r.fail(join(s.field, "output"),
             who + path + " values are " + s.output->format() + "; dpc reads a " + type +
                 " of FLOAT (normalized integer rotations are not supported)");
}

}  // namespace

void checkMeshes(const Level& l) {
  const json& meshes = arrayAt(l, l.json.doc, "", "meshes");
  size_t primitives = 0;
  uint64_t triangles = 0;
  for (size_t m = 0; m < meshes.size(); ++m) {
    const std::string field = index("meshes", m), pf = join(field, "primitives");
    const json& mesh = objectAt(l, meshes, "meshes", m);
    const std::string who = named(mesh, "mesh");
    const json& prims = arrayAt(l, mesh, field, "primitives");
    if (prims.empty()) l.r.fail(pf, who + "a mesh has at least one primitive");
    primitives += prims.size();
    if (primitives > kMaxGltfNodes)
      l.r.fail(pf, "the level's meshes hold more than " + std::to_string(kMaxGltfNodes) +
                       " primitives (the limit)");
    for (size_t k = 0; k < prims.size(); ++k)
      triangles += checkPrimitive(l, objectAt(l, prims, pf, k), index(pf, k), who);
    if (triangles > kMaxGltfTriangles)
      l.r.fail(field, "the level's meshes hold more than " + std::to_string(kMaxGltfTriangles) +
                          " triangles (the limit)");
  }
}

void checkAnimations(const Level& l) {
  const json& animations = arrayAt(l, l.json.doc, "", "animations");
  size_t channels = 0;
  for (size_t a = 0; a < animations.size(); ++a) {
    const std::string field = index("animations", a);
    const json& animation = objectAt(l, animations, "animations", a);
    const std::string who = named(animation, "animation");
    const json& samplerList = arrayAt(l, animation, field, "samplers");
    const json& channelList = arrayAt(l, animation, field, "channels");
    if (samplerList.empty() || channelList.empty())
      l.r.fail(join(field, samplerList.empty() ? "samplers" : "channels"),
               who + "an animation has at least one sampler and one channel");
    channels += channelList.size();
    if (channels > kMaxGltfNodes)
      l.r.fail(join(field, "channels"), "the level's animations hold more than " +
                                            std::to_string(kMaxGltfNodes) +
                                            " channels (the limit)");
    std::vector<Sampler> samplers;
    for (size_t s = 0; s < samplerList.size(); ++s)
      samplers.push_back(checkSampler(l, objectAt(l, samplerList, join(field, "samplers"), s),
                                      index(join(field, "samplers"), s), who));
    std::set<std::pair<size_t, std::string>> targets;
    for (size_t c = 0; c < channelList.size(); ++c)
      checkChannel(l, objectAt(l, channelList, join(field, "channels"), c),
                   index(join(field, "channels"), c), who, samplers, targets);
  }
}

}  // namespace dpc::gltf
