#include "scene/mesh_builder.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "common/input_error.h"
#include "scene/mesh_topology.h"

namespace dpc {
namespace {

/// True for a triangle of zero area or a sliver whose height is below 1e-6 of its longest
/// edge (twice the area below 1e-6 times the longest edge squared), computed in double.
bool degenerate(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 e0 = b - a, e1 = c - a, e2 = c - b;
  const glm::vec3 n =
      glm::vec3(e0.y * e1.z - e0.z * e1.y, e0.z * e1.x - e0.x * e1.z, e0.x * e1.y - e0.y * e1.x);
  const double twiceArea = std::sqrt(double(n.x) * n.x + double(n.y) * n.y + double(n.z) * n.z);
  auto len2 = [](glm::vec3 e) { return double(e.x) * e.x + double(e.y) * e.y + double(e.z) * e.z; };
  const double longest2 = std::max({len2(e0), len2(e1), len2(e2)});
  return !(twiceArea > 1e-6 * longest2);
}

int findMaterial(const std::vector<Material>& materials, const std::string& name) {
  for (size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return int(i);
  return -1;
}

}  // namespace

std::vector<uint32_t> materialIndicesByName(const RawMesh& raw,
                                            const std::vector<Material>& materials,
                                            const std::string& sceneFile) {
  std::vector<uint32_t> slotToMaterial;
  for (const std::string& name : raw.materialNames) {
    const int m = findMaterial(materials, name);
    if (m < 0)
      throw InputError(
          raw.file, raw.materialWord + " " + name,
          "material \"" + name + "\" is not defined in " + sceneFile + " (materials." + name + ")");
    slotToMaterial.push_back(uint32_t(m));
  }
  const int fallback = findMaterial(materials, "default");
  std::vector<uint32_t> out(raw.triangles.size());
  for (size_t t = 0; t < raw.triangles.size(); ++t) {
    const uint32_t slot = raw.triangleMaterial[t];
    if (slot != RawMesh::kNoMaterial) {
      out[t] = slotToMaterial[slot];
    } else if (fallback >= 0) {
      out[t] = uint32_t(fallback);
    } else {
      throw InputError(
          raw.file, raw.faceWord + " " + std::to_string(raw.triangleFace[t]),
          "face has no usemtl and " + sceneFile + " defines no material named \"default\"");
    }
  }
  return out;
}

namespace {

/// The triangle's corners by welded vertex id, rotated to start at the smallest: the same for
/// every triangle on the same three positions with the same winding, whatever its vertex
/// indices. The opposite winding differs: two coincident faces of opposite orientation are
/// how a zero-thickness wall or door is modelled (a side per room), and are kept.
std::array<uint32_t, 3> cornerKey(const std::vector<uint32_t>& weld,
                                  const std::array<uint32_t, 3>& tri) {
  std::array<uint32_t, 3> k{weld[tri[0]], weld[tri[1]], weld[tri[2]]};
  std::rotate(k.begin(), std::min_element(k.begin(), k.end()), k.end());
  return k;
}

struct CornerHash {
  size_t operator()(const std::array<uint32_t, 3>& k) const {
    return size_t(k[0]) * 0x9e3779b97f4a7c15ULL ^ size_t(k[1]) * 0xc2b2ae3d27d4eb4fULL ^
           size_t(k[2]) * 0x165667b19e3779f9ULL;
  }
};

/// "FILE: N <what> triangle(s) dropped, the first from triangle K" into warnings if N > 0.
void warnDropped(const RawMesh& raw, size_t count, size_t first, const std::string& what,
                 std::vector<std::string>& warnings) {
  if (count > 0)
    warnings.push_back(raw.file + ": " + std::to_string(count) + " " + what +
                       " triangle(s) dropped, the first from " + raw.faceWord + " " +
                       std::to_string(first));
}

}  // namespace

Mesh buildMesh(const RawMesh& raw, const std::vector<uint32_t>& materialIndex,
               std::vector<std::string>& warnings) {
  Mesh mesh;
  mesh.vertices = raw.positions;
  const std::vector<uint32_t> weld = weldedVertexIds(mesh);
  std::unordered_set<std::array<uint32_t, 3>, CornerHash> seen;
  seen.reserve(raw.triangles.size());
  size_t dropped = 0, firstDropped = 0, twins = 0, firstTwin = 0;
  for (size_t t = 0; t < raw.triangles.size(); ++t) {
    const std::array<uint32_t, 3>& tri = raw.triangles[t];
    if (degenerate(raw.positions[tri[0]], raw.positions[tri[1]], raw.positions[tri[2]])) {
      if (dropped++ == 0) firstDropped = raw.triangleFace[t];
      continue;
    }
    // A second triangle on the same three positions, facing the same way, adds no surface (a
    // ray hits one of the two), only work: a million copies of one wall made one frame take a
    // minute.
    if (!seen.insert(cornerKey(weld, tri)).second) {
      if (twins++ == 0) firstTwin = raw.triangleFace[t];
      continue;
    }
    mesh.triangles.push_back(tri);
    mesh.materialIndex.push_back(materialIndex[t]);
  }
  if (mesh.triangles.empty())
    throw InputError(raw.file, "",
                     "all " + std::to_string(raw.triangles.size()) +
                         " triangles are degenerate (zero area); nothing to trace");
  warnDropped(raw, dropped, firstDropped, "degenerate (zero-area)", warnings);
  warnDropped(raw, twins, firstTwin, "duplicate (the corners and winding of an earlier one)",
              warnings);
  return mesh;
}

}  // namespace dpc
