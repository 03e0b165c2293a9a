#include "engine/coplanar_faces.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <tsl/robin_map.h>

#include "common/random.h"
#include "scene/mesh_topology.h"

namespace dpc {

namespace {

struct Plane {
  glm::dvec3 n{0.0};
  double d = 0.0;
  bool valid = false;
};

Plane planeOf(const Mesh& m, const std::array<uint32_t, 3>& t) {
  const glm::dvec3 a(m.vertices[t[0]]), b(m.vertices[t[1]]), c(m.vertices[t[2]]);
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double len = glm::length(n);
  if (!(len > 0.0)) return {};
  return {n / len, glm::dot(n / len, a), true};
}

bool samePlane(const Plane& p, const Plane& q) {
  return p.valid && q.valid && glm::dot(p.n, q.n) > CoplanarFaces::kCoplanarCos &&
         std::abs(p.d - q.d) < CoplanarFaces::kCoplanarMetres;
}

/// Edge keys put one vertex in the high word: mix them, as the map's power-of-two buckets use
/// the low bits.
struct EdgeHash {
  size_t operator()(uint64_t k) const { return size_t(mix64(k)); }
};

uint64_t edgeKey(uint32_t a, uint32_t b) {
  return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a;
}

}  // namespace

CoplanarFaces::CoplanarFaces(const std::vector<const Mesh*>& meshes) {
  uint32_t first = 0;
  for (const Mesh* m : meshes) {
    parent_.resize(first + m->triangles.size());
    for (uint32_t t = 0; t < m->triangles.size(); ++t) parent_[first + t] = first + t;
    groupMesh(*m, first);
    first += uint32_t(m->triangles.size());
  }
  face_.resize(parent_.size());
  for (uint32_t t = 0; t < face_.size(); ++t) face_[t] = find(t);
  // The smallest member of each group is its representative: find() keeps roots minimal.
  std::vector<uint32_t> count(face_.size() + 1, 0);
  for (uint32_t f : face_) ++count[f + 1];
  start_.assign(face_.size() + 1, 0);
  for (size_t t = 0; t < face_.size(); ++t) start_[t + 1] = start_[t] + count[t + 1];
  members_.resize(face_.size());
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for (uint32_t t = 0; t < face_.size(); ++t) members_[fill[face_[t]]++] = t;
  parent_ = {};
}

void CoplanarFaces::groupMesh(const Mesh& mesh, uint32_t first) {
  const std::vector<uint32_t> weld = weldedVertexIds(mesh);
  tsl::robin_map<uint64_t, uint32_t, EdgeHash> edgeOwner;  // edge -> a triangle that has it
  edgeOwner.reserve(mesh.triangles.size() * 3);
  std::vector<Plane> planes(mesh.triangles.size());
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) planes[t] = planeOf(mesh, mesh.triangles[t]);
  auto material = [&](uint32_t t) {
    return t < mesh.materialIndex.size() ? mesh.materialIndex[t] : 0u;
  };
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int e = 0; e < 3; ++e) {
      const uint64_t key = edgeKey(weld[tri[size_t(e)]], weld[tri[size_t((e + 1) % 3)]]);
      const auto [it, added] = edgeOwner.emplace(key, t);
      if (added) continue;
      const uint32_t u = it->second;
      if (material(u) != material(t) || !samePlane(planes[u], planes[t])) continue;
      const uint32_t a = find(first + u), b = find(first + t);
      if (a != b) parent_[std::max(a, b)] = std::min(a, b);
    }
  }
}

uint32_t CoplanarFaces::find(uint32_t t) {
  while (parent_[t] != t) {
    parent_[t] = parent_[parent_[t]];
    t = parent_[t];
  }
  return t;
}

std::span<const uint32_t> CoplanarFaces::triangles(uint32_t f) const {
  if (f >= face_.size()) return {};
  return std::span<const uint32_t>(members_.data() + start_[f], start_[f + 1] - start_[f]);
}

}  // namespace dpc
