#include "engine/threaded_legs.h"

#include <algorithm>
#include <array>
#include <glm/geometric.hpp>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "engine/channel_path.h"
#include "engine/edge_chain.h"
#include "engine/gap_probe.h"

namespace dpc {

namespace {

/// m: how far either side of an edge path's leg the gaps it may thread are looked for at least
/// (door gaps are 3 to 20 mm; threadReach widens it to the widest channel's gap), and how far
/// from Q along the leg (Q's own gap is the probe's).
constexpr float kThreadReach = 0.03f;
constexpr float kThreadStart = 0.01f;

/// m: how far either side of a leg the gaps it may thread are looked for: kThreadReach, or the
/// widest gap among the channels (`paths` with slit depth) whose gap is wider than their face
/// is deep, up to kChannelDepthMax. A leg lies somewhere in the gap it threads, so a parallel
/// ray that far to one side meets the gap's far side: the sill's edge path through a 4 cm box
/// leaf's 50 mm undercut, missed at 30 mm, owned the gap as a slit without depth beside the
/// channel (8 dB above the slit model). Not widened for narrower channels: a leaf ajar 13.5
/// degrees lost its rim's path to its side face's channel (20 dB at 63 Hz).
float threadReach(const std::vector<EdgePath>& paths) {
  float reach = kThreadReach;
  for (const EdgePath& p : paths)
    if (p.slit.depth > 0.0 && p.gapWidth > std::max(reach, glm::length(p.through)))
      reach = p.gapWidth;
  return std::min(reach, kChannelDepthMax);
}

/// Rays per path of the threaded-leg test: per leg, two across the edge and two along it.
constexpr size_t kThreadRays = 8;

/// The rays parallel to each leg of p (each leg from Q outward: toward the source, then toward
/// the listener), `reach` either side of it across the edge and along it (a gap that crosses
/// the edge: the slit between two leaves under a lintel), from kThreadStart along the leg;
/// inactive for a leg nearly along the edge or shorter than 2 kThreadStart. `side` receives
/// each ray's unit offset direction.
std::array<TraceRay, kThreadRays> threadRays(const glm::vec3& source, const glm::vec3& L,
                                             const EdgePath& p, float reach,
                                             std::array<glm::vec3, kThreadRays>& side) {
  std::array<TraceRay, kThreadRays> out;
  const std::array<glm::vec3, 2> ends = {source, L};
  for (size_t i = 0; i < 2; ++i) {
    const float length = glm::distance(p.q, ends[i]);
    const glm::vec3 dir = (ends[i] - p.q) / std::max(length, 1e-6f);
    const glm::vec3 across = glm::cross(dir, p.edge->direction);
    const float sine = glm::length(across);
    const glm::vec3 along = p.edge->direction - glm::dot(p.edge->direction, dir) * dir;
    const std::array<glm::vec3, 2> axes = {across / std::max(sine, 1e-6f),
                                           along / std::max(sine, 1e-6f)};
    for (size_t k = 0; k < 4; ++k) {
      const size_t n = 4 * i + k;
      side[n] = (k % 2 == 0 ? 1.f : -1.f) * axes[k / 2];
      out[n] = TraceRay{p.q + kThreadStart * dir + reach * side[n], dir, 0.f,
                        length - kThreadStart - kLegEpsilon,
                        sine > 0.1f && length > 2.f * kThreadStart && !p.atEnd};
    }
  }
  return out;
}

/// Per ray, the first hit on a surface other than its path's edge's own two (a sheet's rim
/// starts a parallel ray just off the sheet when its leg is oblique), in up to three rounds.
std::vector<TraceHit> foreignHits(const BoundQuery& q, const std::vector<EdgePath>& paths,
                                  std::vector<TraceRay> rays) {
  std::vector<TraceHit> hits(rays.size()), found(rays.size());
  for (int round = 0; round < 3; ++round) {
    q.tracer.intersect(rays, hits);
    bool again = false;
    for (size_t i = 0; i < rays.size(); ++i) {
      if (!rays[i].active || !hits[i].found) continue;
      const DiffractionEdge& e = *paths[i / kThreadRays].edge;
      const uint32_t s = surfaceOf(q.surfaces, hits[i].surface.triangle);
      if (s == e.surfaces[0] || s == e.surfaces[1]) {
        rays[i].tnear = hits[i].surface.t + surfaceOffset(rays[i].org, hits[i].surface.t);
        again = true;
        continue;
      }
      found[i] = hits[i];
      rays[i].active = false;
    }
    if (!again) break;
  }
  return found;
}

/// Per parallel ray (threadRays, `reach` off its leg) that met a surface (`hits`), the surface
/// a ray across to the other side of the leg meets within `reach`, from near the leg's point
/// level with the hit (kUnknownSurface: none): the offset leans the hit up to reach tan(angle)
/// past a sheet flush with a thick wall's face, whose reveal lies only before that plane, so
/// four points along the leg are tried.
std::vector<uint32_t> otherSide(const BoundQuery& q, const std::vector<TraceRay>& rays,
                                const std::vector<glm::vec3>& sides,
                                const std::vector<TraceHit>& hits, float reach) {
  const std::array<float, 4> kSteps = {-0.5f * reach, -kGapProbeThrough, kGapProbeThrough,
                                       0.5f * reach};
  const TraceRay idle{glm::vec3(0.f), glm::vec3(1.f, 0.f, 0.f), 0.f, 0.f, false};
  std::vector<TraceRay> across(kSteps.size() * rays.size(), idle), step(across.size(), idle);
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!hits[i].found) continue;
    // From kLegEpsilon on the hit's side of the leg: a leg along a face (a listener in a
    // reveal's plane) has that face on its other side. The step there is checked below.
    const glm::vec3 onLeg = rays[i].org - reach * sides[i] + hits[i].surface.t * rays[i].dir;
    for (size_t k = 0; k < kSteps.size(); ++k) {
      const glm::vec3 from = onLeg + kSteps[k] * rays[i].dir;
      step[kSteps.size() * i + k] = TraceRay{from, sides[i], 0.f, kLegEpsilon};
      across[kSteps.size() * i + k] = TraceRay{from + kLegEpsilon * sides[i], -sides[i], 0.f,
                                               1.05f * reach + kLegEpsilon};
    }
  }
  // A step that crosses a surface puts its start behind the corner the leg grazes within
  // kLegEpsilon (a leaf's rim leg along its own end face): the ray across then starts on the
  // leg, in the air, or it would read the corner's two faces as a gap the leg threads.
  const auto behind = std::make_unique<bool[]>(step.size());
  q.tracer.occluded(step, std::span<bool>(behind.get(), step.size()));
  for (size_t i = 0; i < across.size(); ++i)
    if (behind[i]) across[i] = TraceRay{step[i].org, -step[i].dir, 0.f, 1.05f * reach};
  std::vector<TraceHit> met(across.size());
  q.tracer.intersect(across, met);
  std::vector<uint32_t> out(rays.size(), kUnknownSurface);
  for (size_t i = 0; i < across.size(); ++i)
    if (met[i].found && out[i / kSteps.size()] == kUnknownSurface)
      out[i / kSteps.size()] = surfaceOf(q.surfaces, met[i].surface.triangle);
  return out;
}

/// Marks the edge paths whose leg threads a gap away from Q (a thick wall's jamb seen through
/// the 10 mm gap beside a leaf set in the middle of the wall): a parallel ray threadReach to one
/// side of a leg meets a surface not the edge's own, and from the leg's point level with that
/// hit a ray across to the other side meets one within that reach too. p.threadedBy: those
/// two surfaces. Returns per path the first surface's hit point (m; unset where none).
std::vector<glm::vec3> markThreads(const BoundQuery& q, std::vector<EdgePath>& paths) {
  const float reach = threadReach(paths);
  std::vector<TraceRay> rays;
  std::vector<glm::vec3> sides;
  for (const EdgePath& p : paths) {
    std::array<glm::vec3, kThreadRays> side;
    for (const TraceRay& r : threadRays(q.source, q.L, p, reach, side)) rays.push_back(r);
    sides.insert(sides.end(), side.begin(), side.end());
  }
  const std::vector<TraceHit> hits = foreignHits(q, paths, rays);
  const std::vector<uint32_t> other = otherSide(q, rays, sides, hits, reach);
  std::vector<glm::vec3> at(paths.size(), glm::vec3(0.f));
  for (size_t j = 0; j < paths.size(); ++j)
    for (size_t i = kThreadRays * j; i < kThreadRays * (j + 1); ++i)
      if (other[i] != kUnknownSurface) {
        paths[j].threadedBy = {surfaceOf(q.surfaces, hits[i].surface.triangle), other[i]};
        at[j] = rays[i].org + hits[i].surface.t * rays[i].dir;
        break;
      }
  return at;
}

/// The body of flat surface s (kMovingObjects for a moving object's or an unknown surface).
uint32_t bodyOf(const SurfaceBodies& bodies, uint32_t s) {
  return s < bodies.body.size() ? bodies.body[s] : kMovingObjects;
}

/// Of the two surfaces either side of the gap p's leg threads, the one on another body than p's
/// edge (the leaf beside a jamb), else the first: the gap's closer, whose removal frees the leg.
uint32_t threadCloser(const SurfaceBodies& bodies, const EdgePath& p) {
  for (uint32_t s : p.threadedBy)
    if (bodyOf(bodies, s) != bodyOf(bodies, p.edge->surfaces[0])) return s;
  return p.threadedBy[0];
}

/// m: how far from the edge of the slit that carries it a threaded gap's hit may lie (a channel's
/// depth at most, kChannelDepthMax).
constexpr float kCarryReach = kChannelDepthMax;

}  // namespace

void dropThreadedPaths(BoundQuery& q, std::vector<EdgePath>& paths) {
  // Only a slit can carry a gap: without one (a hall of seats) no leg is looked at.
  if (std::none_of(paths.begin(), paths.end(), [](const EdgePath& p) { return p.gapWidth > 0.f; }))
    return;
  const std::vector<glm::vec3> at = markThreads(q, paths);
  // The slits not threaded themselves, and the bodies either side of each (a leaf and its
  // wall): a slit carries a threaded gap between the same bodies whose hit lies within
  // kCarryReach of its edge (the jamb's own gap, the gap between two leaves under the lintel's
  // point), not one elsewhere on them (a leaf ajar against a door stop: the hinge's slit does
  // not carry the opening at its latch).
  auto body = [&](uint32_t s) { return bodyOf(q.bodies, s); };
  struct Carrier {
    const DiffractionEdge* edge;
    std::vector<uint32_t> bodies;
  };
  std::vector<Carrier> carriers;
  for (const EdgePath& p : paths) {
    if (!(p.gapWidth > 0.f) || p.threadedBy[0] != kUnknownSurface) continue;
    Carrier c{p.edge, {}};
    for (uint32_t s : {p.edge->surfaces[0], p.edge->surfaces[1], p.gapCloser})
      if (s != kUnknownSurface) c.bodies.push_back(body(s));
    carriers.push_back(std::move(c));
  }
  auto isCarried = [&](const EdgePath& p, const glm::vec3& hit) {
    auto by = [&](const Carrier& c, uint32_t s) {
      return s != kUnknownSurface &&
             std::find(c.bodies.begin(), c.bodies.end(), body(s)) != c.bodies.end();
    };
    return std::any_of(carriers.begin(), carriers.end(), [&](const Carrier& c) {
      return by(c, p.threadedBy[0]) && by(c, p.threadedBy[1]) &&
             segmentGap(hit, hit, c.edge->a, c.edge->b) <= kCarryReach;
    });
  };
  size_t kept = 0;
  for (size_t j = 0; j < paths.size(); ++j) {
    EdgePath& p = paths[j];
    if (!isCarried(p, at[j])) {
      paths[kept++] = p;
      continue;
    }
    p.gapCloser = threadCloser(q.bodies, p);
    q.closed.push_back(p);
  }
  paths.resize(kept);
}

}  // namespace dpc
