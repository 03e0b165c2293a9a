#include "engine/surface_bound.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <utility>

#include "engine/coherent_sum.h"
#include "engine/small_bodies.h"

namespace dpc {

namespace {

/// Whether the surfaces that block h's legs are known, searching them the first time.
bool hidersKnown(HiddenPath& h, const BoundQuery& q) {
  if (h.searched) return h.known;
  h.searched = h.known = true;
  std::vector<uint32_t> leg;
  for (const TraceRay& ray : legRays(q.source, q.L, h.path)) {
    if (!crossedSurfaces(q.tracer, ray, q.surfaces, leg)) h.known = false;
    h.by.insert(h.by.end(), leg.begin(), leg.end());
  }
  std::sort(h.by.begin(), h.by.end());
  return h.known;
}

/// Whether the segment of `ray` meets the box grown by kLegEpsilon (slab test).
bool meetsBox(const TraceRay& ray, const std::pair<glm::vec3, glm::vec3>& box) {
  float t0 = ray.tnear, t1 = ray.tfar;
  for (int a = 0; a < 3; ++a) {
    const float lo = box.first[a] - kLegEpsilon, hi = box.second[a] + kLegEpsilon;
    if (std::abs(ray.dir[a]) < 1e-12f) {
      if (ray.org[a] < lo || ray.org[a] > hi) return false;
      continue;
    }
    float ta = (lo - ray.org[a]) / ray.dir[a], tb = (hi - ray.org[a]) / ray.dir[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

/// The boxes round the surfaces (sorted) body by body (SurfaceBodies::body): many small
/// bodies far apart (a hall's seats) leave most legs between their boxes. One box round them
/// all where a surface has no body (the moving objects).
std::vector<std::pair<glm::vec3, glm::vec3>> bodyBoxes(const std::vector<uint32_t>& surfaces,
                                                       const SurfaceBodies& bodies) {
  std::vector<std::pair<uint32_t, uint32_t>> byBody;  // (body, surface)
  for (uint32_t s : surfaces) {
    if (s >= bodies.body.size()) return {boxOfSurfaces(surfaces, bodies)};
    byBody.push_back({bodies.body[s], s});
  }
  std::sort(byBody.begin(), byBody.end());
  std::vector<std::pair<glm::vec3, glm::vec3>> boxes;
  for (size_t i = 0; i < byBody.size();) {
    std::pair<glm::vec3, glm::vec3> box{glm::vec3(1e30f), glm::vec3(-1e30f)};
    size_t j = i;
    for (; j < byBody.size() && byBody[j].first == byBody[i].first; ++j) {
      box.first = glm::min(box.first, bodies.box[byBody[j].second].first);
      box.second = glm::max(box.second, bodies.box[byBody[j].second].second);
    }
    boxes.push_back(box);
    i = j;
  }
  return boxes;
}

/// Edge e with its face on a removed surface taken away: the free rim (a half-plane) of the
/// face that stays, into q.rims; null when both faces or neither go.
const DiffractionEdge* rimOf(const DiffractionEdge& e, const std::vector<uint32_t>& removed,
                             BoundQuery& q) {
  auto gone = [&](uint32_t s) { return std::binary_search(removed.begin(), removed.end(), s); };
  const bool gone0 = gone(e.surfaces[0]), gone1 = gone(e.surfaces[1]);
  if (gone0 == gone1) return nullptr;
  DiffractionEdge& rim = q.rims.emplace_back(e);
  if (gone0) {  // face 1 stays: it becomes face 0
    rim.face0 = std::cos(e.open) * e.face0 + std::sin(e.open) * e.normal0;
    rim.normal0 = glm::normalize(glm::cross(e.direction, rim.face0));
    rim.surfaces = {e.surfaces[1], e.surfaces[1]};
  } else {
    rim.surfaces = {e.surfaces[0], e.surfaces[0]};
  }
  rim.open = float(2.0 * std::numbers::pi);
  // An obstruction taken away (a surface the line of sight crosses: a leaf, welded at its
  // hinge or not) leaves the scene without it, whose frame has a free edge there, its run the
  // wedge's (engine/finite_edge.h). Any other surface is taken away by the small-surface bound
  // (a thick wall's reveal), whose bound holds a sum in which that edge is a wedge, taken as
  // infinite: the rim stays infinite too, so that the two take the edge alike.
  const uint32_t s = gone0 ? e.surfaces[0] : e.surfaces[1];
  if (std::find(q.crossed.begin(), q.crossed.end(), s) == q.crossed.end()) {
    rim.runFrom = -std::numeric_limits<float>::infinity();
    rim.runTo = std::numeric_limits<float>::infinity();
  }
  return &rim;
}

/// The path over edge e's rim when a surface in `removed` takes one of its faces (rimOf), if
/// nothing else blocks its legs, into kept.
void addRim(BoundQuery& q, const DiffractionEdge& e, const std::vector<uint32_t>& removed,
            bool lineOfSight, std::vector<uint32_t>& by, std::vector<EdgePath>& kept) {
  const DiffractionEdge* rim = rimOf(e, removed, q);
  EdgePath p;
  if (!rim || !edgePath(*rim, q.source, q.L, lineOfSight, p)) return;
  findAbsentReflections(q.tracer, q.source, q.L, lineOfSight, p);
  bool free = true;
  for (const TraceRay& ray : legRays(q.source, q.L, p))
    free = free && crossedSurfaces(q.tracer, ray, q.surfaces, by) &&
           std::includes(removed.begin(), removed.end(), by.begin(), by.end());
  if (free) kept.push_back(p);
}

/// The paths over the rims that the surfaces in `removed` leave (rimOf) whose legs nothing
/// else blocks, into kept: the edges on the removed surfaces' faces (SurfaceBodies::edges).
void addRims(BoundQuery& q, const std::vector<uint32_t>& removed, bool lineOfSight,
             std::vector<EdgePath>& kept) {
  std::vector<uint32_t> by;
  for (uint32_t s : removed) {
    if (s >= q.bodies.edges.size()) continue;
    for (uint32_t i : q.bodies.edges[s]) addRim(q, q.edges[i], removed, lineOfSight, by, kept);
  }
}

}  // namespace

std::vector<EdgePath> pathsWithout(const std::vector<EdgePath>& paths, BoundQuery& q,
                                   const std::vector<uint32_t>& removed, bool lineOfSight) {
  auto gone = [&](uint32_t s) { return std::binary_search(removed.begin(), removed.end(), s); };
  auto edgeGone = [&](const EdgePath& p) {  // a channel goes with its face only
    if (p.face != kUnknownSurface) return gone(p.face);
    return gone(p.edge->surfaces[0]) || gone(p.edge->surfaces[1]);
  };
  std::vector<EdgePath> kept;
  for (const EdgePath& p : paths)
    if (!edgeGone(p)) kept.push_back(p);
  for (const EdgePath& p : q.closed)
    if (!edgeGone(p) && gone(p.gapCloser)) kept.push_back(p);
  const auto box = boxOfSurfaces(removed, q.bodies);  // a hider lies in it
  const std::vector<std::pair<glm::vec3, glm::vec3>> boxes = bodyBoxes(removed, q.bodies);
  auto meets = [&](const TraceRay& leg) {
    return meetsBox(leg, box) && std::any_of(boxes.begin(), boxes.end(), [&](const auto& b) {
             return meetsBox(leg, b);
           });
  };
  for (HiddenPath& h : q.hidden) {
    if (edgeGone(h.path)) continue;
    const auto legs = legRays(q.source, q.L, h.path);
    if (!meets(legs[0]) && !meets(legs[1])) continue;
    if (hidersKnown(h, q) && std::all_of(h.by.begin(), h.by.end(), gone)) kept.push_back(h.path);
  }
  addRims(q, removed, lineOfSight, kept);
  for (EdgePath& p : kept) {
    // A free edge whose gap's far side goes is a free edge. A chain's opening (phaseSpread > 0:
    // engine/openings.h) keeps its slit: its chain, which the sum lacks, passes more without
    // that side, not nothing (a wall's face past a leaf's rim, the wall's other face in the way).
    if (p.gapWidth != 0.f && gone(p.gapCloser) && !(p.phaseSpread > 0.f)) p.gapWidth = 0.f;
    p.share = p.atEnd ? 0.0 : 1.0;
    setTerms(lineOfSight, p);
    if (!p.atEnd && !p.corner)
      p.ends = edgeEnds(*p.edge, p.q, q.source, q.L, p.phiS, p.phiL, p.wedge, p.terms);
  }
  markSlitOwners(kept, &q.bodies.body);
  markReveals(q.source, q.L, kept);
  return kept;
}

Bands sumWithout(const std::vector<EdgePath>& paths, BoundQuery& q,
                 const std::vector<uint32_t>& removed, const DirectSound& d, int bands) {
  const std::vector<EdgePath> kept = pathsWithout(paths, q, removed, d.visible);
  const EdgePath* throughSlit = d.visible ? slitOnLineOfSight(kept, q.source, q.L) : nullptr;
  return coherentIntensity(kept, d, throughSlit, q.speedOfSound, q.airPerMetre,
                           leavingWeights(kept, q.directivity, q.forward), bands);
}

namespace {

/// The surfaces (sorted) in the groups that can be taken away on their own: a closed body's
/// together (a solid), the moving objects' together, every other surface alone (a wall's near
/// face without its far face: the wall thinner).
std::vector<std::vector<uint32_t>> removalGroups(const std::vector<uint32_t>& surfaces,
                                                 const SurfaceBodies& bodies) {
  auto key = [&](uint32_t s) -> uint64_t {
    if (s >= bodies.body.size()) return uint64_t(kMovingObjects) << 32;
    const uint32_t b = bodies.body[s];
    return bodies.closed[b] ? (uint64_t(1) << 63) | b : s;
  };
  std::vector<std::vector<uint32_t>> groups;
  std::vector<uint64_t> keys;
  for (uint32_t s : surfaces) {
    const auto at = std::find(keys.begin(), keys.end(), key(s));
    if (at == keys.end()) {
      keys.push_back(key(s));
      groups.push_back({s});
    } else {
      groups[size_t(at - keys.begin())].push_back(s);
    }
  }
  return groups;
}

}  // namespace

std::vector<uint32_t> wholeSolids(const std::vector<uint32_t>& surfaces,
                                  const SurfaceBodies& bodies) {
  std::vector<uint32_t> solid;  // closed bodies met
  for (uint32_t s : surfaces)
    if (s < bodies.body.size() && bodies.closed[bodies.body[s]]) solid.push_back(bodies.body[s]);
  if (solid.empty()) return surfaces;
  std::vector<uint32_t> out = surfaces;
  for (uint32_t b : solid)
    if (b < bodies.members.size())
      out.insert(out.end(), bodies.members[b].begin(), bodies.members[b].end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

/// The scene with the surfaces `removed` (sorted) taken away and the line of sight free, as
/// heldBound holds it there: their sum with the unobstructed direct sound `free`, then its own
/// small surfaces' bound (a thick wall's reveals, a door stop's strips), at most `free`. Else a
/// door closed in a thick wall read 2 dB above the open doorway at 63 Hz, and a box leaf ajar
/// 20-45 degrees against a stop 4 dB above the doorway with the stop, through its chains.
Bands openBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                const Bands& free, const std::vector<uint32_t>& removed, BoundQuery& q) {
  DirectSound open = coherent;
  open.visible = true;
  open.intensity = free;
  const Bands openSum = sumWithout(paths, q, removed, open);
  return min(free, min(openSum, smallSurfaceBound(paths, open, openSum, q, removed)));
}

/// With the line of sight blocked by the surfaces q.crossed (not empty): at most the sum without
/// them, the line of sight free, and without each of them alone (heldBound).
Bands blockedBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                   const Bands& free, BoundQuery& q) {
  const std::vector<uint32_t>& crossed = q.crossed;
  Bands bound = openBound(paths, coherent, free, wholeSolids(crossed, q.bodies), q);
  const std::vector<std::vector<uint32_t>> groups = removalGroups(crossed, q.bodies);
  // Each alone, the others still in the way; but not while a moving object stays in the way:
  // its edges have no first-order paths, so the sum lacks its own field (a leaf left standing
  // with the jamb beside it taken away read 0, and a listener whose line of sight crossed both
  // heard nothing where the same leaf in the mesh passed its gaps). A sum of nothing is no
  // bound either: what stays in the way has no path of its own in the list (a sealed leaf's
  // sides, closed), not a wall that lets nothing round it.
  const bool object = std::find(crossed.begin(), crossed.end(), kMovingObjects) != crossed.end();
  if (groups.size() > 1)
    for (const std::vector<uint32_t>& g : groups) {
      if (object && g.front() != kMovingObjects) continue;
      const Bands without = sumWithout(paths, q, wholeSolids(g, q.bodies), coherent);
      if (without.max() > 0.f) bound = min(bound, without);
    }
  return bound;
}

/// With the line of sight through a slit: at most the sum without either of its sides.
Bands slitBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                const EdgePath& throughSlit, BoundQuery& q) {
  Bands bound(1e30f);
  for (uint32_t s : {throughSlit.edge->surfaces[0], throughSlit.gapCloser})
    if (s != kMovingObjects && s != kUnknownSurface)
      bound = min(bound, sumWithout(paths, q, {s}, coherent));
  return bound;
}

}  // namespace

uint32_t surfaceOf(const std::vector<uint32_t>& surfaces, uint32_t triangle) {
  return triangle < surfaces.size() ? surfaces[triangle] : kMovingObjects;
}

bool crossedSurfaces(const Tracer& tracer, TraceRay ray, const std::vector<uint32_t>& surfaces,
                     std::vector<uint32_t>& out) {
  constexpr int kMaxCrossings = 64;
  out.clear();
  for (int n = 0; n < kMaxCrossings; ++n) {
    SurfaceHit hit;
    if (!tracer.intersect(ray, hit)) {
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
      return true;
    }
    out.push_back(surfaceOf(surfaces, hit.triangle));
    ray.tnear = hit.t + surfaceOffset(ray.org + hit.t * ray.dir, hit.t);
  }
  return false;
}

void crossLineOfSight(bool lineOfSight, BoundQuery& q) {
  q.crossed.clear();
  const glm::vec3 v = q.L - q.source;
  const float length = glm::length(v);
  if (lineOfSight || !(length > 2.f * kLegEpsilon)) return;
  if (!crossedSurfaces(q.tracer, TraceRay{q.source, v / length, kLegEpsilon, length - kLegEpsilon},
                       q.surfaces, q.crossed))
    q.crossed.clear();
}

Bands heldBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                const EdgePath* throughSlit, const Bands& free, const Bands& sum, BoundQuery& q) {
  // Blocked, but by surfaces not known (a grazing segment's crossings): the free field alone.
  if (!coherent.visible && q.crossed.empty()) return free;
  Bands bound = smallSurfaceBound(paths, coherent, sum, q);
  if (!coherent.visible) return min(bound, blockedBound(paths, coherent, free, q));
  // With the line of sight free the moving objects' own edges have no paths, so the sum lacks
  // their lit-side fields, which partly cancel the paths they hide: a sliding door half across
  // its doorway read 4.9 dB above the open doorway at 63 Hz. An obstruction adds no energy: at
  // most the lit-side ripple over the sum with the objects taken away. (Blocked, the sum
  // without them lacks the chains withChains adds later, so it is no bound there.)
  if (q.objects) bound = min(bound, sumWithout(paths, q, {kMovingObjects}, coherent) * kLitRipple);
  if (!throughSlit) return bound;
  return min(bound, slitBound(paths, coherent, *throughSlit, q));
}

namespace {

/// What chainBound takes away whole: each small body q.crossed holds (a pillar meshed as an
/// open tube too) or a chain's edge lies on (a leaf opened 70-80 degrees beside the line of
/// sight, whose chain runs from the hinge jamb round its free rim), and the moving objects
/// together, crossed or carrying a chain (a leaf ajar beside the line of sight, in a
/// partition's doorway); `large`: a large body's face is crossed too.
std::vector<std::vector<uint32_t>> chainGroups(const BoundQuery& q,
                                               const std::vector<ChainEnergy>& chains,
                                               bool& large) {
  std::vector<std::vector<uint32_t>> groups;
  large = false;
  auto add = [&](std::vector<uint32_t> group) {
    if (std::find(groups.begin(), groups.end(), group) == groups.end())
      groups.push_back(std::move(group));
  };
  for (uint32_t s : q.crossed) {
    if (s >= q.bodies.body.size())
      add({kMovingObjects});
    else if (smallBody(q.bodies, s))
      add(q.bodies.members[q.bodies.body[s]]);
    else
      large = true;
  }
  for (const ChainEnergy& c : chains)
    for (uint32_t s : c.surfaces) {
      if (s == kMovingObjects)
        add({kMovingObjects});
      else if (smallBody(q.bodies, s))
        add(q.bodies.members[q.bodies.body[s]]);
    }
  return groups;
}

}  // namespace

Bands chainBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                 const Bands& free, const std::vector<ChainEnergy>& chains, BoundQuery& q) {
  if (coherent.visible || chains.empty() || q.crossed.empty()) return Bands(1e30f);
  bool large = false;
  const std::vector<std::vector<uint32_t>> groups = chainGroups(q, chains, large);
  if (!large) {  // small bodies and objects alone in the way: the scene without them all
    if (groups.empty()) return free;
    std::vector<uint32_t> all;
    for (const std::vector<uint32_t>& g : groups) all.insert(all.end(), g.begin(), g.end());
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    return openBound(paths, coherent, free, all, q);
  }
  Bands bound = free;
  for (const std::vector<uint32_t>& removed : groups) {
    Bands without = sumWithout(paths, q, removed, coherent);
    for (const ChainEnergy& c : chains)
      if (std::none_of(c.surfaces.begin(), c.surfaces.end(), [&](uint32_t s) {
            return std::binary_search(removed.begin(), removed.end(), s);
          }))
        without += c.energy;
    bound = min(bound, without);
  }
  return bound;
}

}  // namespace dpc
