#include "engine/room_volume.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <unordered_map>

#include "scene/mesh_topology.h"

namespace dpc {

double roomVolume(const Mesh& mesh) {
  if (mesh.vertices.empty()) return 1.0;
  glm::dvec3 lo(mesh.vertices[0]), hi(mesh.vertices[0]);
  for (const glm::vec3& v : mesh.vertices) {
    lo = glm::min(lo, glm::dvec3(v));
    hi = glm::max(hi, glm::dvec3(v));
  }
  const glm::dvec3 e = hi - lo;
  const double box = std::max(1.0, e.x * e.y * e.z);
  // Closed: every undirected edge is used by an even number of triangles (2 for a manifold).
  std::unordered_map<uint64_t, int> edges;
  edges.reserve(mesh.triangles.size() * 3);
  const std::vector<uint32_t> id = weldedVertexIds(mesh);  // corners written once per face
  double sixV = 0.0;
  for (const auto& t : mesh.triangles) {
    const glm::dvec3 a(mesh.vertices[t[0]]), b(mesh.vertices[t[1]]), c(mesh.vertices[t[2]]);
    sixV += glm::dot(a - lo, glm::cross(b - lo, c - lo));  // relative to lo: less rounding
    for (int i = 0; i < 3; ++i) {
      const uint64_t u = id[t[size_t(i)]], v = id[t[size_t((i + 1) % 3)]];
      ++edges[u < v ? (u << 32 | v) : (v << 32 | u)];
    }
  }
  for (const auto& [key, count] : edges)
    if (count % 2 != 0) return box;  // open mesh: no enclosed volume
  const double v = std::abs(sixV) / 6.0;
  return v >= 0.01 * box ? std::max(1.0, v) : box;
}

}  // namespace dpc
