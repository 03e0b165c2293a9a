#include "engine/channel_turn.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <utility>
#include <vector>

#include "engine/channel_path.h"
#include "engine/edge_grid.h"

namespace dpc {

void setChannelNeighbours(const std::vector<DiffractionEdge>& edges,
                          std::vector<NarrowFace>& faces) {
  if (faces.empty()) return;
  EdgeGrid grid(edges, kChannelReach);
  for (NarrowFace& f : faces) {
    f.near[0] = parallelNeighbours(edges, f.b, f.a, kChannelReach, kChannelNeighbours,
                                   grid.near(edges[f.b]));
    f.near[1] = parallelNeighbours(edges, f.a, f.b, kChannelReach, kChannelNeighbours,
                                   grid.near(edges[f.a]));
  }
}

namespace {

/// How a mouth is left: the slit's continuation (its first leg when narrow, else zero) and
/// the free legs after it (their offset and total length), m.
struct MouthExit {
  glm::vec3 narrow{0.f}, free{0.f};
  float freeLength = 0.f;
  float narrowWidth = 0.f;  ///< m, the narrow leg's width; 0 when there is none
};

/// The chain's nodes: the feet of m on the edges `near` (square to each, level with m on the
/// parallel ones), those within their edge's length.
std::vector<glm::vec3> chainNodes(const std::vector<DiffractionEdge>& edges,
                                  const std::vector<uint32_t>& near, const glm::vec3& m) {
  std::vector<glm::vec3> at;
  for (uint32_t j : near) {
    const DiffractionEdge& c = edges[j];
    const glm::vec3 x = c.a + glm::dot(m - c.a, c.direction) * c.direction;
    if (withinEdge(c, x)) at.push_back(x);
  }
  return at;
}

/// Shortest chains from m over the nodes, at most kChannelHops legs (each a free segment):
/// per node its length (inf: unreached) and the chain's first node.
struct Chains {
  std::vector<float> cost;
  std::vector<int> first;
};

Chains relaxChains(const Tracer& tracer, const std::vector<glm::vec3>& at, const glm::vec3& m) {
  const size_t n = at.size();
  Chains c{std::vector<float>(n, std::numeric_limits<float>::infinity()), std::vector<int>(n, -1)};
  bool any = false;
  for (size_t j = 0; j < n; ++j)
    if (segmentFree(tracer, m, at[j])) {
      any = true;
      c.cost[j] = glm::distance(m, at[j]);
      c.first[j] = int(j);
    }
  for (int hop = 1; hop < kChannelHops && any; ++hop) {
    Chains next = c;
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n && std::isfinite(c.cost[i]); ++j) {
        const float via = c.cost[i] + glm::distance(at[i], at[j]);
        if (i == j || !(via < next.cost[j]) || !segmentFree(tracer, at[i], at[j])) continue;
        next.cost[j] = via;
        next.first[j] = c.first[i];
      }
    c = std::move(next);
  }
  return c;
}

/// The shortest chain from m (a mouth's point on `edge`) over the edges `near` to a node from
/// which `target` (the listener or the source) is seen; false when none is.
bool leaveMouth(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                const DiffractionEdge& edge, const std::vector<uint32_t>& near,
                const glm::vec3& m, const glm::vec3& target, MouthExit& out) {
  const std::vector<glm::vec3> at = chainNodes(edges, near, m);
  const Chains c = relaxChains(tracer, at, m);
  int best = -1;
  float bestLength = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < at.size(); ++i) {
    const float total = c.cost[i] + glm::distance(at[i], target);
    if (total < bestLength && segmentFree(tracer, at[i], target)) {
      best = int(i);
      bestLength = total;
    }
  }
  if (best < 0) return false;
  const glm::vec3 first = at[size_t(c.first[size_t(best)])];
  const float width = narrowWidth(tracer, edge.direction, m, first, 0.5f);
  const bool narrow = std::isfinite(width);
  out.narrow = narrow ? first - m : glm::vec3(0.f);
  out.narrowWidth = narrow ? width : 0.f;
  out.free = at[size_t(best)] - m - out.narrow;
  out.freeLength = c.cost[size_t(best)] - (narrow ? glm::distance(m, first) : 0.f);
  return true;
}

}  // namespace

bool turnedChannel(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                   const DiffractionEdge& front, const DiffractionEdge& back,
                   const std::vector<uint32_t>& entries, const std::vector<uint32_t>& exits,
                   const glm::vec3& source, const glm::vec3& L, bool open, EdgePath& p) {
  if (entries.empty() && exits.empty()) return false;
  EdgePath straight;
  if (!channelVia(front, back, ChannelTurns{}, source, L, straight) ||
      (!open && !gapAcross(tracer, front, straight.through,
                           glm::dot(straight.q - front.a, front.direction))))
    return false;
  const std::array<TraceRay, 2> legs = legRays(source, L, straight);
  const bool inBlocked = tracer.occluded(legs[0]), outBlocked = tracer.occluded(legs[1]);
  if (!inBlocked && !outBlocked) return false;
  ChannelTurns turns;
  MouthExit e;
  if (inBlocked) {
    if (!leaveMouth(tracer, edges, front, entries, straight.q, source, e)) return false;
    turns.before = -e.narrow;
    turns.beforeWidth = e.narrowWidth;
    turns.lipBefore = -e.free;
    turns.lipBeforeLength = e.freeLength;
  }
  if (outBlocked) {
    if (!leaveMouth(tracer, edges, back, exits, straight.q + straight.through, L, e)) return false;
    turns.beyond = e.narrow;
    turns.beyondWidth = e.narrowWidth;
    turns.lipBeyond = e.free;
    turns.lipBeyondLength = e.freeLength;
  }
  EdgePath c;
  if (!channelVia(front, back, turns, source, L, c) || !legsFree(tracer, source, L, c))
    return false;
  p = c;
  return true;
}

namespace {

/// Whether the ray from a toward b (a leg from Q) is blocked within kChannelReach of a.
bool blockedNear(const Tracer& tracer, const glm::vec3& a, const glm::vec3& b) {
  const float length = glm::distance(a, b);
  return length > kLegEpsilon && tracer.occluded(TraceRay{a, (b - a) / length, kLegEpsilon,
                                                         std::min(kChannelReach, length)});
}

/// Whether the leg `ray` is free, or free moved kGrazing either way square to it and to the
/// edge's direction `along`: a leg that grazes another rim (the leaf's, where it lines up with
/// the jamb and the listener) is not cut off by a tenth of a millimetre.
bool grazingFree(const Tracer& tracer, const TraceRay& ray, const glm::vec3& along) {
  constexpr float kGrazing = 2e-3f;  // m, far below the wavelengths the slit model serves
  if (!tracer.occluded(ray)) return true;
  const glm::vec3 side = glm::normalize(glm::cross(along, ray.dir));
  for (const glm::vec3& d : {side, -side}) {
    TraceRay moved = ray;
    moved.org += kGrazing * d;
    if (!tracer.occluded(moved)) return true;
  }
  return false;
}

}  // namespace

bool turnedLeg(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
               const std::vector<uint32_t>& near, const glm::vec3& source, const glm::vec3& L,
               EdgePath& p) {
  if (near.empty() || p.atEnd) return false;
  const std::array<TraceRay, 2> legs = legRays(source, L, p);
  const bool out = !grazingFree(tracer, legs[1], p.edge->direction);
  if (out == !grazingFree(tracer, legs[0], p.edge->direction)) return false;
  const glm::vec3 target = out ? L : source;
  MouthExit e;
  if (!blockedNear(tracer, p.q, target) ||
      !leaveMouth(tracer, edges, *p.edge, near, p.q, target, e) || e.narrow != glm::vec3(0.f))
    return false;
  const glm::vec3 exit = p.q + e.free;  // the turn's last corner, whence the target is seen
  const float r = glm::distance(source, out ? p.q : exit), s = glm::distance(out ? exit : p.q, L);
  const size_t side = out ? 1 : 0;
  p.lipLength[side] = e.freeLength;
  p.lipExcess[side] =
      std::max(0.f, e.freeLength + glm::distance(exit, target) - glm::distance(p.q, target));
  if (out) {
    p.lipBeyond = e.free;
    p.arrival = (exit - L) / s;
  } else {
    p.lipBefore = -e.free;
    p.leaving = (exit - source) / r;
  }
  p.length = double(r) + double(e.freeLength) + double(s);
  p.legs = float(p.length);
  p.spreading = 0.0;
  p.share = 0.0;
  p.atEnd = true;
  return true;
}

}  // namespace dpc
