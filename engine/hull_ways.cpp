#include "engine/hull_ways.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <limits>

#include "engine/diffraction_edges.h"
#include "engine/edge_path.h"

namespace dpc {

namespace {

/// A point of the plane square to the edges: along the line of sight from the source (x, m),
/// across it (y, m, toward one side), and its edge (none for the source and L).
struct HullPoint {
  float x, y;
  uint32_t edge;
};

constexpr uint32_t kNoEdge = 0xffffffffu;

/// Twice the signed area of the triangle o, a, b: > 0 where b lies left of o -> a.
float cross(const HullPoint& o, const HullPoint& a, const HullPoint& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/// The hull's chain over `points` (sorted by x, the source first and L last, all with y >= 0)
/// that bulges toward +y: its corners' edges between the source and L, in order. A corner
/// turning the way by less than `collinear` radians is none (negative: one turning back by
/// less than that is one).
std::vector<uint32_t> upperChain(const std::vector<HullPoint>& points, float collinear) {
  std::vector<HullPoint> chain;
  for (const HullPoint& p : points) {
    // Pop while the turn at the chain's last corner is not clockwise by `collinear`.
    while (chain.size() >= 2) {
      const HullPoint &o = chain[chain.size() - 2], &a = chain.back();
      const float legs = std::hypot(a.x - o.x, a.y - o.y) * std::hypot(p.x - a.x, p.y - a.y);
      if (cross(o, a, p) < -collinear * legs) break;
      chain.pop_back();
    }
    chain.push_back(p);
  }
  std::vector<uint32_t> out;
  for (const HullPoint& p : chain)
    if (p.edge != kNoEdge) out.push_back(p.edge);
  return out;
}

/// The members of `seeds` parallel to edge `first` (and it).
std::vector<uint32_t> parallelTo(const std::vector<DiffractionEdge>& edges,
                                 const std::vector<uint32_t>& seeds, uint32_t first) {
  std::vector<uint32_t> out;
  for (uint32_t s : seeds)
    if (std::abs(glm::dot(edges[s].direction, edges[first].direction)) >= kParallelEdges)
      out.push_back(s);
  return out;
}

/// m: group edges whose points square to the edges lie this close are one hull corner (the
/// top edges of a row of slats, in line).
constexpr float kSameCorner = 1e-4f;

/// For each corner of `way` (edges of `group` seen along d, the plane's axes e1, e2), the edge
/// among those at the same point (kSameCorner) whose span along d lies nearest the way's point
/// there: the way unfolded about the edges is straight, so its point lies along d as far as
/// its share of the way's length (as engine/edge_chain.h lays it). Over a row of slats in line
/// the way crosses the top of the slat below it, not of whichever slat the hull met first.
void pickDashes(const std::vector<DiffractionEdge>& edges, const std::vector<uint32_t>& group,
                const glm::vec3& source, const glm::vec3& L, const glm::vec3& d,
                const glm::vec3& e1, const glm::vec3& e2, std::vector<uint32_t>& way) {
  auto at = [&](const glm::vec3& p) {
    return glm::vec2(glm::dot(p - source, e1), glm::dot(p - source, e2));
  };
  std::vector<float> cumulative{0.f};
  glm::vec2 last(0.f);
  for (uint32_t i : way) {
    cumulative.push_back(cumulative.back() + glm::distance(last, at(edges[i].a)));
    last = at(edges[i].a);
  }
  const float total = cumulative.back() + glm::distance(last, at(L));
  const float s = glm::dot(source, d), run = glm::dot(L, d) - s;
  if (!(total > 0.f)) return;
  for (size_t k = 0; k < way.size(); ++k) {
    const float along = s + run * cumulative[k + 1] / total;
    const glm::vec2 corner = at(edges[way[k]].a);
    float best = std::numeric_limits<float>::infinity();
    for (uint32_t i : group) {
      if (glm::distance(at(edges[i].a), corner) > kSameCorner) continue;
      const float u = glm::dot(edges[i].a, d), v = glm::dot(edges[i].b, d);
      const float off = std::max({std::min(u, v) - along, along - std::max(u, v), 0.f});
      if (off < best) {
        best = off;
        way[k] = i;
      }
    }
  }
}

/// The ways round one group of parallel edges, one per side of the line of sight.
void groupWays(const std::vector<DiffractionEdge>& edges, const std::vector<uint32_t>& group,
               const glm::vec3& source, const glm::vec3& L,
               std::vector<std::vector<uint32_t>>& out) {
  const glm::vec3 d = edges[group.front()].direction;
  const glm::vec3 sight = (L - source) - glm::dot(L - source, d) * d;
  const float length = glm::length(sight);
  if (!(length > 0.f)) return;  // the line of sight runs along the edges
  const glm::vec3 e1 = sight / length, e2 = glm::cross(d, e1);
  for (float side : {1.f, -1.f}) {
    std::vector<HullPoint> points;
    for (uint32_t i : group) {
      const glm::vec3 v = edges[i].a - source;
      const float x = glm::dot(v, e1), y = side * glm::dot(v, e2);
      if (x > 0.f && x < length && y > 0.f) points.push_back({x, y, i});
    }
    if (points.size() < 2) continue;
    std::sort(points.begin(), points.end(),
              [](const HullPoint& a, const HullPoint& b) { return a.x < b.x; });
    points.insert(points.begin(), HullPoint{0.f, 0.f, kNoEdge});
    points.push_back(HullPoint{length, 0.f, kNoEdge});
    std::vector<uint32_t> way = upperChain(points, kHullCollinear);
    // A listener in line with a body's face (a screen's end) has the way round its two corners
    // or the first-order path round the near one, whose leg runs along the face: both.
    if (way.size() == 1) way = upperChain(points, -kHullCollinear);
    if (way.size() < 2) continue;
    pickDashes(edges, group, source, L, d, e1, side * e2, way);
    out.push_back(std::move(way));
  }
}

constexpr uint32_t kNoBody = 0xffffffffu;

/// The body of edge e's face 0 when it is a small static one (not largeBody), else kNoBody.
uint32_t smallBodyOf(const SurfaceBodies& bodies, const DiffractionEdge& e) {
  const uint32_t s = e.surfaces[0];
  return smallBody(bodies, s) ? bodies.body[s] : kNoBody;
}

/// Body b's edges, each once (an edge lies on two of its faces).
std::vector<uint32_t> bodyEdges(const SurfaceBodies& bodies, uint32_t b) {
  std::vector<uint32_t> out;
  for (uint32_t m : bodies.members[b])
    out.insert(out.end(), bodies.edges[m].begin(), bodies.edges[m].end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

void joinNeighbourBodies(const SurfaceBodies& bodies, const std::vector<DiffractionEdge>& edges,
                         const std::vector<std::vector<uint32_t>>& near,
                         std::vector<uint32_t>& candidates, uint32_t& leftOut) {
  std::vector<uint32_t> joined;  // bodies whose edges are in candidates or `more`, sorted
  for (uint32_t i : candidates) {
    const uint32_t s = edges[i].surfaces[0];
    if (s < bodies.body.size()) joined.push_back(bodies.body[s]);
  }
  std::sort(joined.begin(), joined.end());
  joined.erase(std::unique(joined.begin(), joined.end()), joined.end());
  std::vector<uint32_t> frontier = candidates, more;
  size_t added = 0;
  // Breadth first: the frontier grows as bodies join, and their edges' neighbours are visited.
  for (size_t k = 0; k < frontier.size(); ++k) {
    if (smallBodyOf(bodies, edges[frontier[k]]) == kNoBody) continue;
    for (uint32_t j : near[frontier[k]]) {
      const uint32_t b = smallBodyOf(bodies, edges[j]);
      if (b == kNoBody || std::binary_search(joined.begin(), joined.end(), b)) continue;
      if (++added > kHullBodies) {  // a hull cut off there would invent the group's end
        ++leftOut;
        return;
      }
      joined.insert(std::upper_bound(joined.begin(), joined.end(), b), b);
      const std::vector<uint32_t> own = bodyEdges(bodies, b);  // no other body's edges
      more.insert(more.end(), own.begin(), own.end());
      frontier.insert(frontier.end(), own.begin(), own.end());
    }
  }
  candidates.insert(candidates.end(), more.begin(), more.end());
}

std::vector<std::vector<uint32_t>> hullWays(const std::vector<DiffractionEdge>& edges,
                                            const std::vector<uint32_t>& seeds,
                                            const glm::vec3& source, const glm::vec3& L) {
  std::vector<std::vector<uint32_t>> out;
  std::vector<bool> grouped(seeds.size(), false);
  for (size_t k = 0; k < seeds.size(); ++k) {
    if (grouped[k]) continue;
    const std::vector<uint32_t> group = parallelTo(edges, seeds, seeds[k]);
    for (size_t m = k; m < seeds.size(); ++m)
      grouped[m] = grouped[m] || std::find(group.begin(), group.end(), seeds[m]) != group.end();
    if (group.size() >= 2) groupWays(edges, group, source, L, out);
  }
  return out;
}

}  // namespace dpc
