#include "engine/surface_bound.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>

#include "engine/coherent_sum.h"

namespace dpc {

namespace {

/// Fills every hidden path's blocking surfaces, once.
void findHiders(BoundQuery& q) {
  if (q.hiddenKnown) return;
  q.hiddenKnown = true;
  std::vector<uint32_t> leg;
  for (HiddenPath& h : q.hidden) {
    h.known = true;
    for (const TraceRay& ray : legRays(q.source, q.L, h.path)) {
      if (!crossedSurfaces(q.tracer, ray, q.surfaces, leg)) h.known = false;
      h.by.insert(h.by.end(), leg.begin(), leg.end());
    }
    std::sort(h.by.begin(), h.by.end());
  }
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
  return &rim;
}

/// The paths over the rims that the surfaces in `removed` leave (rimOf) whose legs nothing
/// else blocks, into kept.
void addRims(BoundQuery& q, const std::vector<uint32_t>& removed, bool lineOfSight,
             std::vector<EdgePath>& kept) {
  std::vector<uint32_t> by;
  for (const DiffractionEdge& e : q.edges) {
    const DiffractionEdge* rim = rimOf(e, removed, q);
    EdgePath p;
    if (!rim || !edgePath(*rim, q.source, q.L, lineOfSight, p)) continue;
    bool free = true;
    for (const TraceRay& ray : legRays(q.source, q.L, p))
      free = free && crossedSurfaces(q.tracer, ray, q.surfaces, by) &&
             std::includes(removed.begin(), removed.end(), by.begin(), by.end());
    if (free) kept.push_back(p);
  }
}

/// The paths as they would be with the surfaces in `removed` (sorted) taken away: the edges
/// of their faces dropped, an edge whose other face stays made its rim (addRims); the paths
/// they alone hid, and those whose gap they alone closed, restored; the gaps they closed opened
/// (free edges); the slits' owners, the reveals and the terms (for a line of sight free or not) set
/// again.
std::vector<EdgePath> pathsWithout(const std::vector<EdgePath>& paths, BoundQuery& q,
                                   const std::vector<uint32_t>& removed, bool lineOfSight) {
  auto gone = [&](uint32_t s) { return std::binary_search(removed.begin(), removed.end(), s); };
  auto edgeGone = [&](const EdgePath& p) {
    return gone(p.edge->surfaces[0]) || gone(p.edge->surfaces[1]);
  };
  std::vector<EdgePath> kept;
  for (const EdgePath& p : paths)
    if (!edgeGone(p)) kept.push_back(p);
  for (const EdgePath& p : q.closed)
    if (!edgeGone(p) && gone(p.gapCloser)) kept.push_back(p);
  findHiders(q);
  for (const HiddenPath& h : q.hidden)
    if (h.known && !edgeGone(h.path) && std::all_of(h.by.begin(), h.by.end(), gone))
      kept.push_back(h.path);
  addRims(q, removed, lineOfSight, kept);
  for (EdgePath& p : kept) {
    if (p.gapWidth != 0.f && gone(p.gapCloser)) p.gapWidth = 0.f;
    p.share = p.atEnd ? 0.0 : 1.0;
    setTerms(lineOfSight, p);
  }
  markSlitOwners(kept);
  markReveals(q.source, q.L, kept);
  return kept;
}

/// The coherent sum with the surfaces `removed` taken away (pathsWithout) and the direct sound
/// d (through a slit the line of sight still passes, if any).
Bands sumWithout(const std::vector<EdgePath>& paths, BoundQuery& q,
                 const std::vector<uint32_t>& removed, const DirectSound& d) {
  const std::vector<EdgePath> kept = pathsWithout(paths, q, removed, d.visible);
  const EdgePath* throughSlit = d.visible ? slitOnLineOfSight(kept, q.source, q.L) : nullptr;
  return coherentIntensity(kept, d, throughSlit, q.speedOfSound, q.airPerMetre,
                           leavingWeights(kept, q.directivity, q.forward));
}

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

/// The surfaces (sorted) with every surface of each closed body among them added (a solid
/// goes whole: taken away face by face, a box's side faces would float in the air), sorted.
std::vector<uint32_t> wholeSolids(const std::vector<uint32_t>& surfaces,
                                  const SurfaceBodies& bodies) {
  std::vector<uint32_t> solid;  // closed bodies met
  for (uint32_t s : surfaces)
    if (s < bodies.body.size() && bodies.closed[bodies.body[s]]) solid.push_back(bodies.body[s]);
  if (solid.empty()) return surfaces;
  std::vector<uint32_t> out = surfaces;
  for (uint32_t s = 0; s < bodies.body.size(); ++s)
    if (std::find(solid.begin(), solid.end(), bodies.body[s]) != solid.end()) out.push_back(s);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// The groups of flat surfaces smaller than the longest band's wavelength among the paths'
/// edges' faces and the surfaces that hide a path (each alone, a closed body's whole:
/// wholeSolids), each once, sorted; none that the line of sight crosses (q.crossed: those
/// the blocked line of sight's bounds take away).
std::vector<std::vector<uint32_t>> smallSurfaces(const std::vector<EdgePath>& paths,
                                                 BoundQuery& q) {
  const double longest = q.speedOfSound / bandCentreExactHz(0);
  std::vector<std::vector<uint32_t>> out;
  auto add = [&](uint32_t s) {
    if (s >= q.bodies.body.size() || !(double(q.bodies.extent[s]) < longest)) return;
    std::vector<uint32_t> group = wholeSolids({s}, q.bodies);
    auto crossed = [&](uint32_t g) {
      return std::binary_search(q.crossed.begin(), q.crossed.end(), g);
    };
    if (std::none_of(group.begin(), group.end(), crossed) &&
        std::find(out.begin(), out.end(), group) == out.end())
      out.push_back(std::move(group));
  };
  for (const EdgePath& p : paths)
    for (uint32_t s : p.edge->surfaces) add(s);
  findHiders(q);
  for (const HiddenPath& h : q.hidden)
    for (uint32_t s : h.by) add(s);
  return out;
}

/// Per group of small surfaces (smallSurfaces) that the line of sight does not cross, at most
/// the sum without it times kLitRipple in the bands whose wavelength exceeds its extent
/// (heldBound).
Bands smallSurfaceBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                        BoundQuery& q) {
  Bands bound(1e30f);
  for (const std::vector<uint32_t>& group : smallSurfaces(paths, q)) {
    float extent = 0.f;
    for (uint32_t s : group) extent = std::max(extent, q.bodies.extent[s]);
    const Bands without = sumWithout(paths, q, group, coherent);
    for (int k = 0; k < kNumBands; ++k)
      if (double(extent) < q.speedOfSound / bandCentreExactHz(k))
        bound[k] = std::min(bound[k], kLitRipple * without[k]);
  }
  return bound;
}

/// With the line of sight blocked by the surfaces q.crossed (not empty): at most the sum without
/// them, the line of sight free, and without each of them alone (heldBound).
Bands blockedBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                   const Bands& free, BoundQuery& q) {
  const std::vector<uint32_t>& crossed = q.crossed;
  DirectSound open = coherent;
  open.visible = true;
  open.intensity = free;
  Bands bound = min(free, sumWithout(paths, q, wholeSolids(crossed, q.bodies), open));
  const std::vector<std::vector<uint32_t>> groups = removalGroups(crossed, q.bodies);
  if (groups.size() > 1)  // each alone, the others still in the way
    for (const std::vector<uint32_t>& g : groups)
      bound = min(bound, sumWithout(paths, q, wholeSolids(g, q.bodies), coherent));
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
                const EdgePath* throughSlit, const Bands& free, BoundQuery& q) {
  // Blocked, but by surfaces not known (a grazing segment's crossings): the free field alone.
  if (!coherent.visible && q.crossed.empty()) return free;
  const Bands bound = smallSurfaceBound(paths, coherent, q);
  if (!coherent.visible) return min(bound, blockedBound(paths, coherent, free, q));
  if (!throughSlit) return bound;
  return min(bound, slitBound(paths, coherent, *throughSlit, q));
}

}  // namespace dpc
