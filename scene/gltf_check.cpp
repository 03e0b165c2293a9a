#include "scene/gltf_check.h"

#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/gltf_container.h"
#include "scene/gltf_rules.h"
#include "scene/json_reader.h"
#include "scene/quaternion.h"

namespace dpc {
namespace gltf {
namespace {

using nlohmann::json;

void checkAsset(const Level& l) {
  const json& asset = l.r.require(l.json.doc, "", "asset");
  l.r.expectObject(asset, "asset");
  const std::string version = l.r.string(l.r.require(asset, "asset", "version"), "asset.version");
  if (!version.starts_with("2.") || version.size() < 3)
    l.r.fail("asset.version", inQuotes(version) + "; dpc reads glTF 2.0");
  if (const json* min = JsonReader::find(asset, "minVersion"))
    if (const std::string v = l.r.string(*min, "asset.minVersion"); v != "2.0")
      l.r.fail("asset.minVersion", inQuotes(v) + "; dpc reads glTF 2.0");
}

/// Extensions a level may require that change nothing dpc reads: how surfaces look.
bool looksOnly(const std::string& name) {
  for (const char* prefix : {"KHR_materials_", "KHR_texture_", "EXT_texture_"})
    if (name.starts_with(prefix)) return true;
  return false;
}

void checkExtensions(const Level& l) {
  const json& required = arrayAt(l, l.json.doc, "", "extensionsRequired");
  const json& used = arrayAt(l, l.json.doc, "", "extensionsUsed");
  for (size_t i = 0; i < required.size(); ++i) {
    const std::string field = index("extensionsRequired", i);
    const std::string name = l.r.string(required[i], field);
    if (std::find(used.begin(), used.end(), required[i]) == used.end())
      l.r.fail(field, inQuotes(name) + " is required but not in extensionsUsed");
    if (!looksOnly(name))
      l.r.fail(field, inQuotes(name) +
                          " is required, and dpc (assimp 5.2) does not read it; export without it");
  }
}

void checkBuffers(Level& l) {
  const json& buffers = arrayAt(l, l.json.doc, "", "buffers");
  uint64_t total = 0;
  for (size_t i = 0; i < buffers.size(); ++i) {
    const std::string field = index("buffers", i);
    const json& b = objectAt(l, buffers, "buffers", i);
    const std::string lengthField = join(field, "byteLength");
    const uint64_t declared =
        integer(l, l.r.require(b, field, "byteLength"), lengthField, 1, kMaxMeshBytes);
    const uint64_t held = gltfBufferBytes(l.file, field, b, i, l.json);
    if (held < declared)
      l.r.fail(lengthField,
               std::to_string(declared) + " bytes, but its data holds " + std::to_string(held));
    total += declared;
    if (total > kMaxMeshBytes)
      l.r.fail("buffers", "more than " + std::to_string(kMaxMeshBytes >> 20) +
                              " MiB in all (the limit of a level's data, as of a mesh file)");
    l.bufferBytes.push_back(declared);
  }
}

void checkBufferViews(Level& l) {
  const json& views = arrayAt(l, l.json.doc, "", "bufferViews");
  for (size_t i = 0; i < views.size(); ++i) {
    const std::string field = index("bufferViews", i);
    const json& v = objectAt(l, views, "bufferViews", i);
    View out;
    out.buffer = requiredIndex(l, v, field, "buffer", l.bufferBytes.size(), "buffers");
    out.offset = integerAt(l, v, field, "byteOffset", 0, kMaxMeshBytes, 0);
    out.length = integer(l, l.r.require(v, field, "byteLength"), join(field, "byteLength"), 1,
                         kMaxMeshBytes);
    if (out.offset + out.length > l.bufferBytes[out.buffer])
      l.r.fail(field, "bytes " + std::to_string(out.offset) + " to " +
                          std::to_string(out.offset + out.length) + " lie beyond buffer " +
                          std::to_string(out.buffer) + "'s " +
                          std::to_string(l.bufferBytes[out.buffer]) + " bytes");
    out.stride = integerAt(l, v, field, "byteStride", 4, 252, 0);
    if (out.stride % 4 != 0)
      l.r.fail(join(field, "byteStride"), std::to_string(out.stride) + " is not a multiple of 4");
    if (const json* target = JsonReader::find(v, "target"))
      if (const uint64_t t = integer(l, *target, join(field, "target"), 0, UINT32_MAX);
          t != 34962 && t != 34963)
        l.r.fail(join(field, "target"), std::to_string(t) +
                                            " is neither 34962 (ARRAY_BUFFER) nor 34963 "
                                            "(ELEMENT_ARRAY_BUFFER)");
    l.views.push_back(out);
  }
}

/// The accessor's component type, type, normalisation and count.
Accessor accessorFormat(const Level& l, const json& a, const std::string& field) {
  Accessor out;
  const std::string componentField = join(field, "componentType");
  const uint64_t code =
      integer(l, l.r.require(a, field, "componentType"), componentField, 0, UINT32_MAX);
  out.component = componentType(code);
  if (!out.component)
    l.r.fail(componentField,
             std::to_string(code) + " is not a glTF component type " + componentTypeList());
  const std::string typeField = join(field, "type");
  const std::string type = l.r.string(l.r.require(a, field, "type"), typeField);
  out.type = elementType(type);
  if (!out.type)
    l.r.fail(typeField, inQuotes(type) +
                            " is not a glTF accessor type (SCALAR, VEC2, VEC3, "
                            "VEC4, MAT2, MAT3, MAT4)");
  if (const json* n = JsonReader::find(a, "normalized"))
    out.normalized = l.r.boolean(*n, join(field, "normalized"));
  if (out.normalized && (code == kFloat || code == kUnsignedInt))
    l.r.fail(join(field, "normalized"),
             std::string("true for ") + out.component->name +
                 "; only BYTE, UNSIGNED_BYTE, SHORT and UNSIGNED_SHORT are normalized");
  out.count = integer(l, l.r.require(a, field, "count"), join(field, "count"), 1, UINT32_MAX);
  return out;
}

/// min and max, if given: one finite number per component; out.bounds when both are.
void accessorBounds(const Level& l, const json& a, const std::string& field, Accessor& out) {
  int given = 0;
  for (const char* key : {"min", "max"}) {
    const json* v = JsonReader::find(a, key);
    if (!v) continue;
    (void)numbers(l, *v, join(field, key), out.type->components);
    ++given;
  }
  out.bounds = given == 2;
}

/// Where the accessor's elements lie: all inside its bufferView, aligned to the component.
void accessorPlace(const Level& l, const json& a, const std::string& field, Accessor& out) {
  if (a.contains("sparse"))
    l.r.fail(join(field, "sparse"), "sparse accessors are not supported (export without them)");
  const auto view = indexAt(l, a, field, "bufferView", l.views.size(), "bufferViews");
  if (!view)
    l.r.fail(join(field, "bufferView"),
             "missing: an accessor without a bufferView (all zeros) is not supported");
  out.view = *view;
  const View& v = l.views[out.view];
  const uint64_t bytes = out.component->bytes, element = bytes * out.type->components;
  const uint64_t offset = integerAt(l, a, field, "byteOffset", 0, kMaxMeshBytes, 0);
  if (offset % bytes != 0 || (v.offset + offset) % bytes != 0)
    l.r.fail(join(field, "byteOffset"),
             std::to_string(offset) + " (in its buffer: " + std::to_string(v.offset + offset) +
                 ") is not a multiple of the component's " + std::to_string(bytes) + " bytes");
  const uint64_t stride = v.stride ? v.stride : element;
  if (stride < element)
    l.r.fail(field, "its elements of " + std::to_string(element) +
                        " bytes are longer than its bufferView's byteStride " +
                        std::to_string(stride));
  const uint64_t end = offset + stride * (out.count - 1) + element;
  if (end > v.length)
    l.r.fail(join(field, "count"),
             std::to_string(out.count) + " elements of " + std::to_string(element) +
                 " bytes (stride " + std::to_string(stride) + ") from byteOffset " +
                 std::to_string(offset) + " need " + std::to_string(end) + " bytes; bufferView " +
                 std::to_string(out.view) + " holds " + std::to_string(v.length));
}

void checkAccessors(Level& l) {
  const json& accessors = arrayAt(l, l.json.doc, "", "accessors");
  for (size_t i = 0; i < accessors.size(); ++i) {
    const std::string field = index("accessors", i);
    const json& a = objectAt(l, accessors, "accessors", i);
    Accessor out = accessorFormat(l, a, field);
    accessorBounds(l, a, field, out);
    accessorPlace(l, a, field, out);
    l.accessors.push_back(out);
  }
}

void checkImages(const Level& l) {
  const json& images = arrayAt(l, l.json.doc, "", "images");
  for (size_t i = 0; i < images.size(); ++i) {
    const std::string field = index("images", i);
    const json& image = objectAt(l, images, "images", i);
    if (const json* uri = JsonReader::find(image, "uri"))
      checkGltfImageUri(l.file, join(field, "uri"), l.r.string(*uri, join(field, "uri")));
    (void)indexAt(l, image, field, "bufferView", l.views.size(), "bufferViews");
  }
}

/// True when the column-major 4x4 `m` is a translation, rotation and scale (what glTF allows a
/// node's matrix to be): its last row (0, 0, 0, 1), its first three columns of non-zero length
/// and at right angles (within float rounding of a composed matrix); mirroring is allowed.
bool isTrs(const std::vector<double>& m) {
  if (m[3] != 0 || m[7] != 0 || m[11] != 0 || m[15] != 1) return false;
  auto dot = [&](int a, int b) {
    return m[4 * a] * m[4 * b] + m[4 * a + 1] * m[4 * b + 1] + m[4 * a + 2] * m[4 * b + 2];
  };
  for (int a = 0; a < 3; ++a) {
    if (!(dot(a, a) > 0)) return false;
    for (int b = a + 1; b < 3; ++b)
      if (std::abs(dot(a, b)) > 1e-4 * std::sqrt(dot(a, a) * dot(b, b))) return false;
  }
  return true;
}

/// A node's matrix, or its translation, rotation (of non-zero length) and scale.
void checkNodeTransform(const Level& l, const json& n, const std::string& field,
                        const std::string& who) {
  if (const json* matrix = JsonReader::find(n, "matrix")) {
    for (const char* key : {"translation", "rotation", "scale"})
      if (n.contains(key))
        l.r.fail(join(field, key), who + "given with a matrix; glTF 2.0 takes one or the other");
    if (!isTrs(numbers(l, *matrix, join(field, "matrix"), 16)))
      l.r.fail(join(field, "matrix"), who +
                                          "is not a translation, rotation and scale (a zero "
                                          "scale, a skew or a projection), as glTF requires");
    return;
  }
  if (const json* t = JsonReader::find(n, "translation"))
    (void)numbers(l, *t, join(field, "translation"), 3);
  if (const json* s = JsonReader::find(n, "scale")) (void)numbers(l, *s, join(field, "scale"), 3);
  if (const json* r = JsonReader::find(n, "rotation")) {
    const std::vector<double> q = numbers(l, *r, join(field, "rotation"), 4);
    if (!unitQuaternion(q[0], q[1], q[2], q[3]))
      l.r.fail(join(field, "rotation"),
               who + r->dump() + " has zero length; a rotation needs a unit quaternion");
  }
}

/// A node's own fields; records it as the parent of its children.
void checkNode(Level& l, const json& nodes, size_t i) {
  const std::string field = index("nodes", i);
  const json& n = objectAt(l, nodes, "nodes", i);
  const std::string who = named(n, "node");
  if (n.contains("skin"))
    l.r.fail(join(field, "skin"), who +
                                      "skinned meshes are not supported (their triangles "
                                      "follow joints; dpc needs rigid geometry)");
  (void)indexAt(l, n, field, "mesh", arrayAt(l, l.json.doc, "", "meshes").size(), "meshes", who);
  (void)indexAt(l, n, field, "camera", arrayAt(l, l.json.doc, "", "cameras").size(), "cameras",
                who);
  checkNodeTransform(l, n, field, who);
  const json& children = arrayAt(l, n, field, "children");
  for (size_t k = 0; k < children.size(); ++k) {
    const std::string childField = index(join(field, "children"), k);
    const size_t c = indexValue(l, children[k], childField, nodes.size(), "nodes", who);
    if (c == i) l.r.fail(childField, who + "a node cannot be its own child");
    if (l.parent[c] >= 0)
      l.r.fail(childField, who + "node " + std::to_string(c) + " is already a child of node " +
                               std::to_string(l.parent[c]) + "; a node has one parent");
    l.parent[c] = int64_t(i);
  }
}

/// Walks the forest from its roots without recursion: every node within kMaxGltfNodeDepth
/// levels, and none left over (a node never reached lies on a cycle).
void checkNodeDepth(const Level& l, const json& nodes) {
  std::vector<uint32_t> depth(nodes.size(), 0);
  std::vector<size_t> stack;
  for (size_t root = 0; root < nodes.size(); ++root) {
    if (l.parent[root] >= 0) continue;
    depth[root] = 1;
    stack.push_back(root);
    while (!stack.empty()) {
      const size_t k = stack.back();
      stack.pop_back();
      for (const json& c : arrayAt(l, nodes[k], "", "children")) {
        const size_t child = c.get<size_t>();
        depth[child] = depth[k] + 1;
        if (depth[child] > uint32_t(kMaxGltfNodeDepth))
          l.r.fail(index("nodes", child),
                   named(nodes[child], "node") + "lies more than " +
                       std::to_string(kMaxGltfNodeDepth) +
                       " levels deep in the node tree (the limit: the tree is walked "
                       "recursively)");
        stack.push_back(child);
      }
    }
  }
  for (size_t i = 0; i < nodes.size(); ++i)
    if (depth[i] == 0)
      l.r.fail(index("nodes", i) + ".children", "the node is its own ancestor (a cycle)");
}

void checkNodes(Level& l) {
  const json& nodes = arrayAt(l, l.json.doc, "", "nodes");
  l.parent.assign(nodes.size(), -1);
  for (size_t i = 0; i < nodes.size(); ++i) checkNode(l, nodes, i);
  checkNodeDepth(l, nodes);
  if (nodes.size() > kMaxGltfNodes)
    l.r.fail("nodes", std::to_string(nodes.size()) + " nodes, more than the limit of " +
                          std::to_string(kMaxGltfNodes));
}

void checkScenes(const Level& l) {
  const json& scenes = arrayAt(l, l.json.doc, "", "scenes");
  (void)indexAt(l, l.json.doc, "", "scene", scenes.size(), "scenes");
  for (size_t s = 0; s < scenes.size(); ++s) {
    const std::string field = join(index("scenes", s), "nodes");
    const json& roots = arrayAt(l, objectAt(l, scenes, "scenes", s), index("scenes", s), "nodes");
    std::set<size_t> seen;
    for (size_t k = 0; k < roots.size(); ++k) {
      const size_t n = indexValue(l, roots[k], index(field, k), l.parent.size(), "nodes");
      if (l.parent[n] >= 0)
        l.r.fail(index(field, k), "node " + std::to_string(n) + " is a child of node " +
                                      std::to_string(l.parent[n]) + "; a scene lists roots");
      if (!seen.insert(n).second)
        l.r.fail(index(field, k), "node " + std::to_string(n) + " is listed twice");
    }
  }
}

}  // namespace
}  // namespace gltf

nlohmann::json checkGltfLevel(const std::string& file) {
  gltf::Level l(file);
  l.json = readGltfJson(file);
  gltf::checkAsset(l);
  gltf::checkExtensions(l);
  gltf::checkBuffers(l);
  gltf::checkBufferViews(l);
  gltf::checkAccessors(l);
  gltf::checkImages(l);
  gltf::checkMeshes(l);
  gltf::checkNodes(l);
  gltf::checkScenes(l);
  gltf::checkAnimations(l);
  return std::move(l.json.doc);
}

}  // namespace dpc
