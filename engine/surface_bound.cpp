#include "engine/surface_bound.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>
#include <utility>

#include "engine/coherent_sum.h"

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

/// The path over edge e's rim when a surface in `removed` takes one of its faces (rimOf), if
/// nothing else blocks its legs, into kept.
void addRim(BoundQuery& q, const DiffractionEdge& e, const std::vector<uint32_t>& removed,
            bool lineOfSight, std::vector<uint32_t>& by, std::vector<EdgePath>& kept) {
  const DiffractionEdge* rim = rimOf(e, removed, q);
  EdgePath p;
  if (!rim || !edgePath(*rim, q.source, q.L, lineOfSight, p)) return;
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

/// The paths as they would be with the surfaces in `removed` (sorted) taken away: the edges
/// of their faces dropped, an edge whose other face stays made its rim (addRims); the paths
/// they alone hid, and those whose gap they alone closed, restored; the gaps they closed opened
/// (free edges); the slits' owners, the reveals and the terms (for a line of sight free or not) set
/// again.
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
  for (HiddenPath& h : q.hidden) {
    if (edgeGone(h.path)) continue;
    const auto legs = legRays(q.source, q.L, h.path);
    if (!meetsBox(legs[0], box) && !meetsBox(legs[1], box)) continue;
    if (hidersKnown(h, q) && std::all_of(h.by.begin(), h.by.end(), gone)) kept.push_back(h.path);
  }
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
/// d (through a slit the line of sight still passes, if any), in the first `bands` bands.
Bands sumWithout(const std::vector<EdgePath>& paths, BoundQuery& q,
                 const std::vector<uint32_t>& removed, const DirectSound& d,
                 int bands = kNumBands) {
  const std::vector<EdgePath> kept = pathsWithout(paths, q, removed, d.visible);
  const EdgePath* throughSlit = d.visible ? slitOnLineOfSight(kept, q.source, q.L) : nullptr;
  return coherentIntensity(kept, d, throughSlit, q.speedOfSound, q.airPerMetre,
                           leavingWeights(kept, q.directivity, q.forward), bands);
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
  for (uint32_t b : solid)
    if (b < bodies.members.size())
      out.insert(out.end(), bodies.members[b].begin(), bodies.members[b].end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// A group of flat surfaces for smallSurfaceBound: the surfaces (sorted), the largest extent
/// among those that stand free (m; freeStandingExtents) and the least path-length excess over
/// the direct distance of their edges' paths (m).
struct SmallGroup {
  std::vector<uint32_t> surfaces;
  float extent = 0.f;
  double excess = 1e30;
};

/// The surfaces taken away with free-standing surface s (sorted): its whole body when the body
/// is less than `wavelength` across (a seat's boxes, a box leaf: a small object goes whole), else
/// s alone (a leaf welded to its wall), a closed body's faces together (wholeSolids).
std::vector<uint32_t> smallGroupOf(uint32_t s, double wavelength, const SurfaceBodies& bodies) {
  const uint32_t b = bodies.body[s];
  if (b < bodies.members.size()) {
    const auto [lo, hi] = boxOfSurfaces(bodies.members[b], bodies);
    if (double(glm::distance(lo, hi)) < wavelength) return bodies.members[b];
  }
  return wholeSolids({s}, bodies);
}

/// The groups of free-standing flat surfaces smaller than the longest band's wavelength with an
/// edge path inside that band's first Fresnel zone (excess under half its wavelength) among the
/// paths' edges' faces (smallGroupOf); none that the line of sight crosses (q.crossed: those the
/// blocked line of sight's bounds take away).
std::vector<SmallGroup> smallSurfaces(const std::vector<EdgePath>& paths, const BoundQuery& q) {
  const double longest = q.speedOfSound / bandCentreExactHz(0);
  const double direct = double(glm::distance(q.source, q.L));
  std::vector<SmallGroup> out;
  auto crossed = [&](uint32_t g) { return std::binary_search(q.crossed.begin(), q.crossed.end(), g); };
  for (const EdgePath& p : paths) {
    const double excess = p.length - direct;
    if (p.atEnd || !(excess < 0.5 * longest)) continue;
    for (uint32_t s : p.edge->surfaces) {
      if (s >= q.bodies.extent.size() || !(double(q.bodies.extent[s]) < longest)) continue;
      std::vector<uint32_t> group = smallGroupOf(s, longest, q.bodies);
      if (std::any_of(group.begin(), group.end(), crossed)) continue;
      auto at = std::find_if(out.begin(), out.end(),
                             [&](const SmallGroup& g) { return g.surfaces == group; });
      if (at == out.end()) {
        float extent = 0.f;  // of the faces that stand free (a box's bottom on the floor does not)
        for (uint32_t g : group)
          if (std::isfinite(q.bodies.extent[g])) extent = std::max(extent, q.bodies.extent[g]);
        at = out.insert(out.end(), SmallGroup{std::move(group), extent, excess});
      }
      at->excess = std::min(at->excess, excess);
    }
  }
  return out;
}

/// The bands (the lowest ones) where a group's bound applies: its extent under the wavelength,
/// its least path excess under half of it.
int smallBands(const SmallGroup& group, float speedOfSound) {
  int bands = 0;
  while (bands < kNumBands) {
    const double wavelength = speedOfSound / bandCentreExactHz(bands);
    if (!(double(group.extent) < wavelength && group.excess < 0.5 * wavelength)) break;
    ++bands;
  }
  return bands;
}

/// Whether the group's own edge paths (their band amplitudes `amplitude`, bandAmplitude) carry,
/// in each of the first `bands` bands, at most kSmallShare of the sum's pressure: taking them
/// away cannot lower the sum to 1 / kLitRipple of itself, so the bound cannot hold it.
bool weakGroup(const std::vector<EdgePath>& paths, const std::vector<Bands>& amplitude,
               const SmallGroup& group, int bands, const Bands& sum) {
  // (1 - s)^2 kLitRipple >= 1 for s <= 1 - 1 / sqrt(1.37) = 0.146.
  constexpr double kSmallShare = 0.14;
  const auto& g = group.surfaces;
  for (int k = 0; k < bands; ++k) {
    double own = 0.0;
    for (size_t j = 0; j < paths.size(); ++j)
      if (std::binary_search(g.begin(), g.end(), paths[j].edge->surfaces[0]) ||
          std::binary_search(g.begin(), g.end(), paths[j].edge->surfaces[1]))
        own += double(amplitude[j][k]);
    if (own > kSmallShare * std::sqrt(4.0 * std::numbers::pi * double(sum[k]))) return false;
  }
  return true;
}

/// Per group of small surfaces (smallSurfaces), at most the sum without it times kLitRipple in
/// the bands whose wavelength exceeds its extent and twice its least path excess (heldBound);
/// `sum` the coherent sum with everything in place but the surfaces `base` (sorted; the groups
/// are those of the paths without them, and each group goes with them).
Bands smallSurfaceBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                        const Bands& sum, BoundQuery& q, const std::vector<uint32_t>& base = {}) {
  Bands bound(1e30f);
  const std::vector<EdgePath> kept =
      base.empty() ? paths : pathsWithout(paths, q, base, coherent.visible);
  const std::vector<SmallGroup> groups = smallSurfaces(kept, q);
  int most = 0;
  for (const SmallGroup& group : groups) most = std::max(most, smallBands(group, q.speedOfSound));
  std::vector<Bands> amplitude(kept.size(), Bands(0.f));  // each path's, once
  for (size_t j = 0; j < kept.size(); ++j)
    for (int k = 0; k < most; ++k) amplitude[j][k] = float(bandAmplitude(kept[j], k, q.speedOfSound));
  for (const SmallGroup& group : groups) {
    const int bands = smallBands(group, q.speedOfSound);
    if (bands == 0 || weakGroup(kept, amplitude, group, bands, sum)) continue;
    std::vector<uint32_t> removed = base;
    removed.insert(removed.end(), group.surfaces.begin(), group.surfaces.end());
    std::sort(removed.begin(), removed.end());
    removed.erase(std::unique(removed.begin(), removed.end()), removed.end());
    const Bands without = sumWithout(paths, q, removed, coherent, bands);
    for (int k = 0; k < bands; ++k) bound[k] = std::min(bound[k], kLitRipple * without[k]);
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
  // The open configuration as heldBound holds it with its line of sight free: the surfaces
  // the line of sight crosses taken away, then its own small surfaces' bound (a thick wall's
  // reveals): else a door closed in a thick wall read 2 dB above the open doorway at 63 Hz.
  const std::vector<uint32_t> removed = wholeSolids(crossed, q.bodies);
  const Bands openSum = sumWithout(paths, q, removed, open);
  Bands bound = min(free, min(openSum, smallSurfaceBound(paths, open, openSum, q, removed)));
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
                const EdgePath* throughSlit, const Bands& free, const Bands& sum, BoundQuery& q) {
  // Blocked, but by surfaces not known (a grazing segment's crossings): the free field alone.
  if (!coherent.visible && q.crossed.empty()) return free;
  const Bands bound = smallSurfaceBound(paths, coherent, sum, q);
  if (!coherent.visible) return min(bound, blockedBound(paths, coherent, free, q));
  if (!throughSlit) return bound;
  return min(bound, slitBound(paths, coherent, *throughSlit, q));
}

namespace {

/// What chainBound takes away whole: each small body q.crossed holds (a pillar meshed as an
/// open tube too) and the moving objects together, crossed or carrying a chain (a leaf ajar
/// beside the line of sight, in a partition's doorway); `large`: a large body's face is
/// crossed too.
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
    else if (q.bodies.body[s] < q.bodies.members.size() && !largeBody(q.bodies, s))
      add(q.bodies.members[q.bodies.body[s]]);
    else
      large = true;
  }
  for (const ChainEnergy& c : chains)
    if (std::find(c.surfaces.begin(), c.surfaces.end(), kMovingObjects) != c.surfaces.end())
      add({kMovingObjects});
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
    DirectSound open = coherent;
    open.visible = true;
    open.intensity = free;
    return min(free, sumWithout(paths, q, all, open));
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
