#include "engine/diffraction_edges.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <limits>
#include <numbers>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "engine/finite_edge.h"
#include "engine/sealed_edges.h"
#include "scene/mesh_topology.h"

namespace dpc {

namespace {

constexpr double kPi = std::numbers::pi;

glm::vec3 safeNormalize(const glm::vec3& v) {
  const float l = glm::length(v);
  return l > 0.f ? v / l : glm::vec3(0.f);
}

/// Undirected edge (welded vertex ids, smaller first, as one key) -> the triangles using it.
struct EdgeUse {
  std::vector<uint32_t> tris;
};

/// Per triangle, whether an earlier triangle has the same three welded corners: the back of a
/// double-sided face (an exporter's two-sided material, a sheet written once per side). Its
/// edges are the front's: counted twice they would make every edge of the face non-manifold,
/// and a doorway in a double-sided wall would diffract nothing.
std::vector<bool> duplicateFaces(const Mesh& mesh, const std::vector<uint32_t>& id) {
  std::unordered_map<uint64_t, std::vector<std::array<uint32_t, 3>>> seen;
  std::vector<bool> duplicate(mesh.triangles.size(), false);
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    std::array<uint32_t, 3> c{id[mesh.triangles[t][0]], id[mesh.triangles[t][1]],
                              id[mesh.triangles[t][2]]};
    std::sort(c.begin(), c.end());
    auto& bucket = seen[uint64_t(c[0]) << 32 | c[1]];
    duplicate[t] = std::find(bucket.begin(), bucket.end(), c) != bucket.end();
    if (!duplicate[t]) bucket.push_back(c);
  }
  return duplicate;
}

std::unordered_map<uint64_t, EdgeUse> edgeUses(const Mesh& mesh, const std::vector<uint32_t>& id) {
  std::unordered_map<uint64_t, EdgeUse> uses;
  uses.reserve(mesh.triangles.size() * 3);
  const std::vector<bool> duplicate = duplicateFaces(mesh, id);
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int i = 0; i < 3 && !duplicate[t]; ++i) {
      const uint64_t u = id[mesh.triangles[t][size_t(i)]],
                     v = id[mesh.triangles[t][size_t((i + 1) % 3)]];
      uses[u < v ? (u << 32 | v) : (v << 32 | u)].tris.push_back(t);
    }
  return uses;
}

glm::vec3 normalOf(const Mesh& mesh, uint32_t t) {
  const auto& tr = mesh.triangles[t];
  return safeNormalize(glm::cross(mesh.vertices[tr[1]] - mesh.vertices[tr[0]],
                                  mesh.vertices[tr[2]] - mesh.vertices[tr[0]]));
}

/// In-plane unit vector of triangle t from the edge (ia, ib) toward its third vertex.
glm::vec3 inward(const Mesh& mesh, const std::vector<uint32_t>& id, uint32_t t, uint32_t ia,
                 uint32_t ib, const glm::vec3& dir) {
  const auto& tr = mesh.triangles[t];
  uint32_t third = tr[0];
  for (uint32_t v : tr)
    if (id[v] != ia && id[v] != ib) third = v;
  glm::vec3 w = mesh.vertices[third] - mesh.vertices[ia];
  w -= glm::dot(w, dir) * dir;
  return safeNormalize(w);
}

/// The faces that end at an edge: per flat surface among its triangles, one of them, unless
/// the surface's triangles lie on both sides of the edge (it runs on across it). At most two.
struct EdgeFaces {
  std::array<uint32_t, 2> tri{};
  int count = 0;
  bool valid = false;  // false: a surface runs across (interior or a T-junction), or three ends
};

/// The copies of one sheet (its two sides written as triangles of their own, not exact
/// duplicates) end at its rim as one face; a leaf welded to its frame at the hinge and the
/// frame are two faces there, a wedge, though four triangles use the edge.
EdgeFaces endingFaces(const Mesh& mesh, const std::vector<uint32_t>& id,
                      const std::vector<uint32_t>& surfaces, uint32_t ia, uint32_t ib,
                      const glm::vec3& direction, const EdgeUse& use) {
  EdgeFaces f;
  std::array<glm::vec3, 2> side{};
  for (uint32_t t : use.tris) {
    const glm::vec3 w = inward(mesh, id, t, ia, ib, direction);
    int k = 0;
    while (k < f.count && surfaces[f.tri[size_t(k)]] != surfaces[t]) ++k;
    if (k < f.count) {
      if (glm::dot(w, side[size_t(k)]) < 0.f) return f;  // runs on across the edge
      continue;
    }
    if (f.count == 2) return f;  // a third surface
    f.tri[size_t(f.count)] = t;
    side[size_t(f.count++)] = w;
  }
  f.valid = f.count > 0;
  return f;
}

/// The candidate edge of welded edge `key`; false when it has no wedge (degenerate, flat, or
/// where a surface runs on across it or three surfaces meet).
bool makeEdge(const Mesh& mesh, const std::vector<uint32_t>& id,
              const std::vector<uint32_t>& surfaces, uint64_t key, const EdgeUse& use,
              DiffractionEdge& e) {
  const uint32_t ia = uint32_t(key >> 32), ib = uint32_t(key & 0xffffffffu);
  e.a = mesh.vertices[ia];
  e.b = mesh.vertices[ib];
  e.length = glm::length(e.b - e.a);
  if (!(e.length > 0.f)) return false;
  e.direction = (e.b - e.a) / e.length;
  const EdgeFaces faces = endingFaces(mesh, id, surfaces, ia, ib, e.direction, use);
  if (!faces.valid) return false;
  e.face0 = inward(mesh, id, faces.tri[0], ia, ib, e.direction);
  e.normal0 = normalOf(mesh, faces.tri[0]);
  e.surfaces = {surfaces[faces.tri[0]], surfaces[faces.tri[size_t(faces.count - 1)]]};
  if (glm::length(e.face0) == 0.f || glm::length(e.normal0) == 0.f) return false;
  if (faces.count == 1) {
    e.open = float(2.0 * kPi);  // half-plane: one wedge of 2 pi
    return true;
  }
  // Angle of face 1 from face 0, turning toward normal0. Which of the two wedges
  // (open, 2 pi - open) holds air is decided per frame by where the source is, so the
  // mesh's winding does not matter.
  const glm::vec3 f1 = inward(mesh, id, faces.tri[1], ia, ib, e.direction);
  double ang = std::atan2(double(glm::dot(f1, e.normal0)), double(glm::dot(f1, e.face0)));
  if (ang < 0) ang += 2.0 * kPi;
  e.open = float(ang);
  return !(std::abs(ang - kPi) < kFlatEdge);  // flat: no wedge
}

/// Lexicographic order of the endpoints: a deterministic edge order (the hash map's is not).
bool edgeBefore(const DiffractionEdge& x, const DiffractionEdge& y) {
  if (x.a.x != y.a.x) return x.a.x < y.a.x;
  if (x.a.y != y.a.y) return x.a.y < y.a.y;
  if (x.a.z != y.a.z) return x.a.z < y.a.z;
  if (x.b.x != y.b.x) return x.b.x < y.b.x;
  if (x.b.y != y.b.y) return x.b.y < y.b.y;
  return x.b.z < y.b.z;
}

}  // namespace

std::vector<uint32_t> flatSurfaces(const Mesh& mesh) {
  const std::vector<uint32_t> id = weldedVertexIds(mesh);
  std::unordered_map<uint64_t, std::vector<uint32_t>> users;  // welded edge -> its triangles
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) {
      const uint64_t u = id[mesh.triangles[t][size_t(i)]],
                     v = id[mesh.triangles[t][size_t((i + 1) % 3)]];
      users[u < v ? (u << 32 | v) : (v << 32 | u)].push_back(t);
    }
  std::vector<uint32_t> parent(mesh.triangles.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&parent](uint32_t t) {
    while (parent[t] != t) t = parent[t] = parent[parent[t]];
    return t;
  };
  const double flat = std::cos(kFlatEdge);
  for (const auto& [key, ts] : users)
    for (size_t i = 0; i < ts.size(); ++i)
      for (size_t j = i + 1; j < ts.size(); ++j) {
        if (!(std::abs(double(glm::dot(normalOf(mesh, ts[i]), normalOf(mesh, ts[j])))) > flat))
          continue;
        const uint32_t a = root(ts[i]), b = root(ts[j]);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
  std::vector<uint32_t> number(mesh.triangles.size(), UINT32_MAX), surface(number.size());
  uint32_t next = 0;
  for (uint32_t t = 0; t < surface.size(); ++t) {
    uint32_t& n = number[root(t)];
    if (n == UINT32_MAX) n = next++;
    surface[t] = n;
  }
  return surface;
}

namespace {

/// Per flat surface, its triangles' bounding box (m).
std::vector<std::pair<glm::vec3, glm::vec3>> surfaceBoxes(const Mesh& mesh,
                                                          const std::vector<uint32_t>& surfaces) {
  const size_t count =
      surfaces.empty() ? 0 : size_t(*std::max_element(surfaces.begin(), surfaces.end())) + 1;
  std::vector<std::pair<glm::vec3, glm::vec3>> box(count, {glm::vec3(1e30f), glm::vec3(-1e30f)});
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (uint32_t v : mesh.triangles[t]) {
      box[surfaces[t]].first = glm::min(box[surfaces[t]].first, mesh.vertices[v]);
      box[surfaces[t]].second = glm::max(box[surfaces[t]].second, mesh.vertices[v]);
    }
  return box;
}

/// Per body, whether it is a solid object: closed and less than kSolidExtent across (a room is
/// closed too, and larger; which side of it is air its winding cannot tell: exporters differ).
std::vector<bool> solidBodies(const SurfaceBodies& bodies) {
  std::vector<bool> solid(bodies.closed.size());
  for (size_t b = 0; b < solid.size(); ++b) {
    const auto [lo, hi] = boxOfSurfaces(bodies.members[b], bodies);
    solid[b] = bodies.closed[b] && glm::distance(lo, hi) < kSolidExtent;
  }
  return solid;
}

/// SurfaceBodies::outward: per body, the sign of the volume its triangles enclose (the sum of
/// the tetrahedra from its box's corner to each, the divergence theorem) where it is a solid
/// object; +1 where that volume is not clearly signed (under a tenth of the tetrahedra's
/// volumes taken unsigned: a double-sided copy cancels its face, mixed windings) or the body
/// is none.
std::vector<float> outwardSigns(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                                const SurfaceBodies& bodies) {
  const size_t n = bodies.members.size();
  std::vector<double> volume(n, 0.0), unsigned_(n, 0.0);
  const std::vector<bool> solid = solidBodies(bodies);
  std::vector<glm::dvec3> corner(n);
  for (size_t b = 0; b < n; ++b)
    if (solid[b]) corner[b] = boxOfSurfaces(bodies.members[b], bodies).first;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const uint32_t b = bodies.body[surfaces[t]];
    if (b >= n || !solid[b]) continue;
    const glm::dvec3 v0 = mesh.vertices[mesh.triangles[t][0]];
    const glm::dvec3 e1 = glm::dvec3(mesh.vertices[mesh.triangles[t][1]]) - v0;
    const glm::dvec3 e2 = glm::dvec3(mesh.vertices[mesh.triangles[t][2]]) - v0;
    const double v = glm::dot(v0 - corner[b], glm::cross(e1, e2)) / 6.0;
    volume[b] += v;
    unsigned_[b] += std::abs(v);
  }
  std::vector<float> out(n, 1.f);
  for (size_t b = 0; b < n; ++b)
    if (solid[b] && volume[b] < -0.1 * unsigned_[b]) out[b] = -1.f;
  return out;
}

}  // namespace

SurfaceBodies surfaceBodies(const Mesh& mesh, const std::vector<uint32_t>& surfaces) {
  const std::vector<uint32_t> id = weldedVertexIds(mesh);
  std::vector<uint32_t> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&parent](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& t : mesh.triangles)
    for (size_t i = 1; i < 3; ++i) {
      const uint32_t a = root(id[t[0]]), b = root(id[t[i]]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  const uint32_t count =
      surfaces.empty() ? 0u : *std::max_element(surfaces.begin(), surfaces.end()) + 1u;
  SurfaceBodies out{std::vector<uint32_t>(count, UINT32_MAX), {}, {}, {}, {}, {}, {}};
  std::unordered_map<uint32_t, uint32_t> number;  // vertex root -> body
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const uint32_t r = root(id[mesh.triangles[t][0]]);
    const uint32_t b = number.try_emplace(r, uint32_t(number.size())).first->second;
    if (out.body[surfaces[t]] == UINT32_MAX) out.body[surfaces[t]] = b;
  }
  out.box = surfaceBoxes(mesh, surfaces);
  out.members.resize(number.size());
  for (uint32_t s = 0; s < count; ++s)
    if (out.body[s] != UINT32_MAX) out.members[out.body[s]].push_back(s);
  out.closed.assign(number.size(), true);
  for (const auto& [key, use] : edgeUses(mesh, id)) {  // a free rim opens its body
    const uint32_t ia = uint32_t(key >> 32), ib = uint32_t(key & 0xffffffffu);
    const glm::vec3 d = mesh.vertices[ib] - mesh.vertices[ia];
    if (!(glm::length(d) > 0.f)) continue;
    const EdgeFaces f = endingFaces(mesh, id, surfaces, ia, ib, glm::normalize(d), use);
    if (f.valid && f.count == 1) out.closed[out.body[surfaces[f.tri[0]]]] = false;
  }
  out.outward = outwardSigns(mesh, surfaces, out);
  return out;
}

namespace {

/// Whether edge e bounds its faces as a free-standing surface's rim does: a sheet's free rim,
/// any edge of an open body (sheets with air on both sides: the edge diffracts into the wider
/// side, whichever way the faces are wound), any edge of a solid; not a room's (a closed body
/// that is no solid: its corners are concave from inside).
bool diffracts(const DiffractionEdge& e, const std::vector<bool>& solid,
               const SurfaceBodies& bodies) {
  if (double(e.open) >= 2.0 * std::numbers::pi - 1e-3) return true;
  const uint32_t body = bodies.body[e.surfaces[0]];
  return !bodies.closed[body] || solid[body];
}

}  // namespace

std::vector<double> surfaceBoundaries(const Mesh& mesh, const std::vector<uint32_t>& surfaces) {
  const size_t count =
      surfaces.empty() ? 0 : size_t(*std::max_element(surfaces.begin(), surfaces.end())) + 1;
  const std::vector<uint32_t> id = weldedVertexIds(mesh);
  // Each surface's triangles once (a double-sided copy has the same corners), then their sides
  // as (surface, welded corners): a side used once is the surface's boundary.
  std::vector<std::array<uint32_t, 4>> triangles, sides;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    std::array<uint32_t, 4> k{surfaces[t], id[mesh.triangles[t][0]], id[mesh.triangles[t][1]],
                              id[mesh.triangles[t][2]]};
    std::sort(k.begin() + 1, k.end());
    triangles.push_back(k);
  }
  std::sort(triangles.begin(), triangles.end());
  triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
  for (const auto& k : triangles)
    for (int i = 0; i < 3; ++i)
      sides.push_back({k[0], k[1 + i], k[1 + (i + 1) % 3], 0});
  for (auto& x : sides)
    if (x[1] > x[2]) std::swap(x[1], x[2]);
  std::sort(sides.begin(), sides.end());
  std::vector<double> boundary(count, 0.0);
  for (size_t i = 0; i < sides.size();) {
    size_t j = i;
    while (j < sides.size() && sides[j] == sides[i]) ++j;
    if (j - i == 1 && sides[i][1] != sides[i][2])
      boundary[sides[i][0]] +=
          double(glm::distance(mesh.vertices[sides[i][1]], mesh.vertices[sides[i][2]]));
    i = j;
  }
  return boundary;
}

std::vector<float> freeStandingExtents(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                                       const SurfaceBodies& bodies,
                                       const std::vector<DiffractionEdge>& edges) {
  const std::vector<double> boundary = surfaceBoundaries(mesh, surfaces);
  const size_t count = boundary.size();
  std::vector<double> diffracting(count, 0.0);
  const std::vector<bool> solid = solidBodies(bodies);
  for (const DiffractionEdge& e : edges) {
    if (!diffracts(e, solid, bodies)) continue;
    diffracting[e.surfaces[0]] += double(e.length);
    if (e.surfaces[1] != e.surfaces[0]) diffracting[e.surfaces[1]] += double(e.length);
  }
  std::vector<float> extent(count, std::numeric_limits<float>::infinity());
  for (size_t s = 0; s < count; ++s)
    if (boundary[s] > 0.0 && diffracting[s] >= kFreeStanding * boundary[s])
      extent[s] = glm::distance(bodies.box[s].first, bodies.box[s].second);
  return extent;
}

std::pair<glm::vec3, glm::vec3> boxOfSurfaces(const std::vector<uint32_t>& surfaces,
                                              const SurfaceBodies& bodies) {
  std::pair<glm::vec3, glm::vec3> box{glm::vec3(1e30f), glm::vec3(-1e30f)};
  for (uint32_t s : surfaces) {
    if (s >= bodies.box.size()) return {glm::vec3(-1e30f), glm::vec3(1e30f)};
    box.first = glm::min(box.first, bodies.box[s].first);
    box.second = glm::max(box.second, bodies.box[s].second);
  }
  return box;
}

bool largeBody(const SurfaceBodies& bodies, uint32_t s) {
  if (s >= bodies.body.size() || bodies.body[s] >= bodies.members.size()) return false;
  const auto [lo, hi] = boxOfSurfaces(bodies.members[bodies.body[s]], bodies);
  return glm::distance(lo, hi) >= kSolidExtent;
}

bool smallBody(const SurfaceBodies& bodies, uint32_t s) {
  return s < bodies.body.size() && bodies.body[s] < bodies.members.size() && !largeBody(bodies, s);
}

std::vector<std::vector<uint32_t>> surfaceEdges(size_t surfaceCount,
                                                const std::vector<DiffractionEdge>& edges) {
  std::vector<std::vector<uint32_t>> out(surfaceCount);
  for (size_t i = 0; i < edges.size(); ++i)
    for (uint32_t s : {edges[i].surfaces[0], edges[i].surfaces[1]})
      if (s < surfaceCount && (out[s].empty() || out[s].back() != uint32_t(i)))
        out[s].push_back(uint32_t(i));
  return out;
}

std::vector<DiffractionEdge> candidateEdges(const Mesh& mesh,
                                           const std::vector<uint32_t>& surfaces) {
  const std::vector<uint32_t> id = weldedVertexIds(mesh);
  const SealingSurfaces sealing(mesh);
  std::vector<DiffractionEdge> edges;
  for (const auto& [key, use] : edgeUses(mesh, id)) {
    DiffractionEdge e;
    if (makeEdge(mesh, id, surfaces, key, use, e))
      sealing.appendOpenParts(e, *std::min_element(use.tris.begin(), use.tris.end()), surfaces,
                              edges);
  }
  std::sort(edges.begin(), edges.end(), edgeBefore);
  setEdgeRuns(edges);
  return edges;
}

}  // namespace dpc
