#include "engine/surface_bound.h"

#include <algorithm>
#include <glm/geometric.hpp>

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

/// The paths as they would be with the surfaces in `removed` (sorted) taken away: those
/// surfaces' edges dropped; the paths they alone hid, and those whose gap they alone closed,
/// restored; the gaps they closed opened (free edges); the slits' owners, the reveals and the
/// terms (for a line of sight free or not) set again.
std::vector<EdgePath> pathsWithout(const std::vector<EdgePath>& paths, BoundQuery& q,
                                   const std::vector<uint32_t>& removed, bool lineOfSight) {
  auto gone = [&](uint32_t s) { return std::binary_search(removed.begin(), removed.end(), s); };
  std::vector<EdgePath> kept;
  for (const EdgePath& p : paths)
    if (!gone(p.edge->surface)) kept.push_back(p);
  for (const EdgePath& p : q.closed)
    if (!gone(p.edge->surface) && gone(p.gapCloser)) kept.push_back(p);
  findHiders(q);
  for (const HiddenPath& h : q.hidden)
    if (h.known && !gone(h.path.edge->surface) && std::all_of(h.by.begin(), h.by.end(), gone))
      kept.push_back(h.path);
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

Bands heldBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                const EdgePath* throughSlit, const Bands& free, BoundQuery& q) {
  if (!coherent.visible) {
    const glm::vec3 v = q.L - q.source;
    const float length = glm::length(v);
    std::vector<uint32_t> crossed;
    if (!(length > 2.f * kLegEpsilon) ||
        !crossedSurfaces(q.tracer,
                         TraceRay{q.source, v / length, kLegEpsilon, length - kLegEpsilon},
                         q.surfaces, crossed) ||
        crossed.empty())
      return free;
    DirectSound open = coherent;
    open.visible = true;
    open.intensity = free;
    return min(free, sumWithout(paths, q, crossed, open));
  }
  Bands bound(1e30f);
  if (!throughSlit) return bound;
  for (uint32_t s : {throughSlit->edge->surface, throughSlit->gapCloser})
    if (s != kMovingObjects && s != kUnknownSurface)
      bound = min(bound, sumWithout(paths, q, {s}, coherent));
  return bound;
}

}  // namespace dpc
