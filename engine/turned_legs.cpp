#include "engine/turned_legs.h"

#include <algorithm>
#include <glm/geometric.hpp>

#include "engine/channel_path.h"
#include "engine/channel_turn.h"
#include "engine/diffraction_edges.h"
#include "engine/gap_probe.h"
#include "engine/path_slits.h"

namespace dpc {

namespace {

/// The edges of `near` whose lines pass within kChannelReach of p's point Q, on neither p's
/// edge's body nor `closer`'s (the surface across p's gap: a turn round the leaf is the leaf's
/// channel).
std::vector<uint32_t> lipEdges(const std::vector<DiffractionEdge>& edges,
                               const std::vector<uint32_t>& near, const EdgePath& p,
                               const SurfaceBodies& bodies, uint32_t closer) {
  std::vector<uint32_t> out;
  for (uint32_t j : near) {
    const DiffractionEdge& f = edges[j];
    const glm::vec3 off = p.q - f.a - glm::dot(p.q - f.a, f.direction) * f.direction;
    if (glm::length(off) <= kChannelReach && !onEdgeBody(bodies.body, f, p.edge->surfaces[0]) &&
        !onEdgeBody(bodies.body, f, p.edge->surfaces[1]) && !onEdgeBody(bodies.body, f, closer))
      out.push_back(j);
  }
  return out;
}

/// The distance (m) from p's point Q to the nearest line among `rims` parallel to p's edge,
/// Q's foot within that rim, seen from Q across free air, if less than `within`; else
/// `within`. `skip(j)` leaves rim j out.
template <class Skip>
float nearestRim(const Tracer& tracer, const EdgePath& p, const std::vector<DiffractionEdge>& rims,
                 float within, Skip skip) {
  float best = within;
  for (uint32_t j = 0; j < uint32_t(rims.size()); ++j) {
    const DiffractionEdge& f = rims[j];
    if (std::abs(glm::dot(f.direction, p.edge->direction)) < kParallelEdges || skip(j)) continue;
    const float t = glm::dot(p.q - f.a, f.direction);
    const glm::vec3 foot = f.a + t * f.direction;
    const float d = glm::distance(p.q, foot);
    if (t >= 0.f && t <= f.length && d > kGapNarrowest && d < best &&
        segmentFree(tracer, p.q, foot))
      best = d;
  }
  return best;
}

/// Path p's slit width (m): the probe's, or the nearest rim of another body (static, not on
/// p's edge's body nor among its turn's edges `lip`, or a moving object's) where nearer.
float openingWidth(const std::vector<DiffractionEdge>& edges, const std::vector<uint32_t>& lip,
                   const std::vector<ObjectEdges>& objects, const BoundQuery& q,
                   const EdgePath& p) {
  const size_t i = edgeIndex(edges, p);
  float w = nearestRim(q.tracer, p, edges, p.gapWidth, [&](uint32_t j) {
    return j == i || std::find(lip.begin(), lip.end(), j) != lip.end() ||
           onEdgeBody(q.bodies.body, edges[j], p.edge->surfaces[0]) ||
           onEdgeBody(q.bodies.body, edges[j], p.edge->surfaces[1]);
  });
  for (const ObjectEdges& o : objects)
    w = nearestRim(q.tracer, p, o.world, w, [](uint32_t) { return false; });
  return w;
}

/// Hidden path p (its gap probed) turned round the edges beside it, with its slit as wide as
/// its opening (openingWidth), without depth, along its edge; false when it does not turn or
/// the opening is wider than the way to the turn's corner (the stop then stands inside the
/// opening's mouth, not past it: the leaf's rim and its openings take it, engine/openings.h).
bool turnAndOpen(const std::vector<DiffractionEdge>& edges,
                 const std::vector<std::vector<uint32_t>>& near,
                 const std::vector<ObjectEdges>& objects, const BoundQuery& q, EdgePath& p) {
  const std::vector<uint32_t> lip =
      lipEdges(edges, near[edgeIndex(edges, p)], p, q.bodies, p.gapCloser);
  if (!(p.gapWidth > 0.f) || !turnedLeg(q.tracer, edges, lip, q.source, q.L, p)) return false;
  const float w = openingWidth(edges, lip, objects, q, p);
  if (w > glm::length(p.lipBeyond + p.lipBefore)) return false;
  slitAlongEdge(w, q.source + p.lipBefore, q.L - p.lipBeyond, p);
  return true;
}

}  // namespace

void addTurnedLegs(const std::vector<DiffractionEdge>& edges,
                   const std::vector<std::vector<uint32_t>>& near,
                   const std::vector<ObjectEdges>& objects, BoundQuery& q,
                   std::vector<EdgePath>& paths) {
  std::vector<EdgePath> found, closed;
  for (const HiddenPath& h : q.hidden) {  // those that turn, before any probe
    EdgePath p = h.path;
    const size_t i = edgeIndex(edges, p);
    if (i < edges.size() && largeBody(q.bodies, p.edge->surfaces[0]) &&
        turnedLeg(q.tracer, edges, lipEdges(edges, near[i], p, q.bodies, kUnknownSurface),
                  q.source, q.L, p))
      found.push_back(h.path);
  }
  if (found.empty()) return;
  findSlits(q.tracer, q.source, q.L, q.surfaces, found, closed, &q.bodies);  // gap, closer
  for (EdgePath& p : found) {
    if (!turnAndOpen(edges, near, objects, q, p)) continue;
    paths.push_back(p);
    std::erase_if(q.hidden, [&](const HiddenPath& h) { return h.path.edge == p.edge; });
  }
}

}  // namespace dpc
