#include "engine/openings.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/geometric.hpp>
#include <numbers>

#include "engine/channel_path.h"
#include "engine/diffraction_edges.h"
#include "engine/slit.h"

namespace dpc {

namespace {

constexpr double kPi = std::numbers::pi;

/// m: how far a point may lie from an edge's line to be on it (a chain's first point on a
/// channel's front edge, an opening's rim on a channel's mouth).
constexpr float kOnEdge = 2e-3f;

/// cos 60 degrees: how squarely a surface must face the leg to close an opening across it, and
/// how squarely a chain's step must cross a channel's face to take its route.
constexpr float kSquarely = 0.5f;

/// The fan of rays looking for an opening: degrees from the leg, away from the turn. The rays
/// from kFanWide on (past 60) look for a large body's face only: a wall's face a few
/// millimetres ahead of a leaf's rim lies far round from the leg, but so does the next post of
/// a row beside the path, whose slot is no opening (the posts' own paths and floors hold it).
constexpr std::array<float, 17> kFanDegrees = {5.f,  10.f, 15.f, 20.f, 25.f, 30.f,
                                               35.f, 40.f, 45.f, 50.f, 55.f, 60.f,
                                               65.f, 70.f, 75.f, 80.f, 85.f};
constexpr size_t kFanWide = 12;

/// x with its component along the unit vector d taken out.
glm::vec3 square(const glm::vec3& x, const glm::vec3& d) { return x - glm::dot(x, d) * d; }

/// The wavenumber (rad/m) of diffraction frequency i of band b.
double wavenumber(int b, int i, float speedOfSound) {
  return 2.0 * kPi * diffractionFrequencyHz(b, i) / double(speedOfSound);
}

/// The open channel (a path along a narrow face whose gap the probe found: engine/channel_path.h)
/// whose route chain c takes, round the face's front edge and across it to the back edge; null
/// when none (a leaf ajar a few degrees: the chain round its latch end's two rims). The
/// chain's edges run along the channel's (a way over a row of slats' tops, whose point lies
/// at a vertical slot's top end, is not that slot's channel).
const EdgePath* channelOf(const EdgeChain& c, const std::vector<EdgePath>& paths) {
  if (c.n != 2) return nullptr;
  const glm::vec3 step = c.q[1] - c.q[0];
  for (const EdgePath& p : paths) {
    if (!(p.gapWidth > 0.f) || p.through == glm::vec3(0.f)) continue;
    const DiffractionEdge& e = *p.edge;
    if (std::abs(glm::dot(e.direction, c.ends[0].direction)) < kParallelEdges) continue;
    const glm::vec3 across = square(step, e.direction);
    const float depth = glm::length(across);
    if (glm::length(square(c.q[0] - e.a, e.direction)) < kOnEdge && depth <= kChannelDepthMax &&
        glm::dot(across, glm::normalize(p.through)) > kSquarely * depth)
      return &p;
  }
  return nullptr;
}

/// (1 - s)^2 per band, averaged over its frequencies, for the slit path p (slitShare).
Bands unslitShare(const EdgePath& p, float speedOfSound) {
  Bands out;
  for (int b = 0; b < kNumBands; ++b) {
    double sum = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const double s = slitShare(p, wavenumber(b, i, speedOfSound));
      sum += (1.0 - s) * (1.0 - s);
    }
    out[b] = float(sum / kDiffractionFrequenciesPerBand);
  }
  return out;
}

/// An opening beside an edge: its width (m), the unit direction across it from the edge, and
/// the flat surface met there.
struct Opening {
  float width = 0.f;
  glm::vec3 mouth{0.f};
  uint32_t surface = kUnknownSurface;
};

/// Whether edge e is a small body's or a moving object's: a leaf, a crate, a pillar. A large
/// body's edge (a wall's) keeps its free field: its openings are the probe's.
bool smallEdge(const BoundQuery& q, const DiffractionEdge& e) {
  const uint32_t s = e.surfaces[0];
  return s == kMovingObjects || smallBody(q.bodies, s);
}

/// m: how far from edge e a slit's opening is looked for (kOpeningReach, and at least
/// kSlitMinAspect times as long as wide), and a wider one another path's slit may be
/// (kPartnerReach, at least twice as long as wide).
float slitReach(const DiffractionEdge& e) {
  return std::min(kOpeningReach, e.length / float(kSlitMinAspect));
}
float partnerReach(const DiffractionEdge& e) { return std::min(kPartnerReach, 0.5f * e.length); }

/// The fan's rays from B: square to e, kFanDegrees from the unit leg direction u toward the
/// unit direction v, `reach` metres long.
std::array<TraceRay, kFanDegrees.size()> fan(const glm::vec3& B, const glm::vec3& u,
                                             const glm::vec3& v, float reach) {
  std::array<TraceRay, kFanDegrees.size()> rays;
  for (size_t i = 0; i < rays.size(); ++i) {
    const float a = glm::radians(kFanDegrees[i]);
    rays[i] = TraceRay{B, std::cos(a) * u + std::sin(a) * v, surfaceOffset(B), reach};
  }
  return rays;
}

/// The nearest surface the fan from B (kFanDegrees from the unit leg direction u toward the
/// unit direction v) meets that faces the leg within 60 degrees and is not e's own body (past
/// kFanWide, a large body's only).
Opening openingAlong(const BoundQuery& q, const DiffractionEdge& e, const glm::vec3& B,
                     const glm::vec3& u, const glm::vec3& v, float reach) {
  const auto rays = fan(B, u, v, reach);
  std::array<TraceHit, kFanDegrees.size()> hits;
  q.tracer.intersect(rays, hits);
  Opening o;
  for (size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].found) continue;
    const uint32_t s = surfaceOf(q.surfaces, hits[i].surface.triangle);
    if (std::abs(glm::dot(hits[i].surface.normal, u)) < kSquarely || onEdgeBody(q.bodies.body, e, s)) continue;
    if (i >= kFanWide && !largeBody(q.bodies, s)) continue;
    const glm::vec3 across = square(hits[i].surface.t * rays[i].dir, e.direction);
    if (const float w = glm::length(across); w > 0.f && (o.width == 0.f || w < o.width))
      o = {w, across / w, s};
  }
  return o;
}

/// The opening beside edge e at point B, for the leg from B toward T, the path arriving from A
/// (it turns round e's solid toward that side; the fan looks the other way), within `reach`
/// metres: the nearest surface that faces the leg within 60 degrees (a wall's face past a
/// leaf's rim; not a reveal the leg runs along and leaves) and is not e's own body. Width 0:
/// none.
Opening openingAt(const BoundQuery& q, const DiffractionEdge& e, const glm::vec3& B,
                  const glm::vec3& A, const glm::vec3& T, float reach) {
  const glm::vec3 out = square(T - B, e.direction), in = square(B - A, e.direction);
  if (!(glm::length(out) > 0.f) || !(glm::length(in) > 0.f)) return {};
  const glm::vec3 u = glm::normalize(out);
  const glm::vec3 turn = square(u - glm::normalize(in), u);
  if (glm::length(turn) < 1e-3f) return {};  // no turn: no side to look at
  return openingAlong(q, e, B, u, -glm::normalize(turn), reach);
}

/// The opening beside edge e at B across the leg toward T on the side away from e's solid (its
/// faces' bisector), for a leg that grazes e's corner and so barely turns there (a leaf's rim
/// ajar a few degrees, the leg on to the reveal's far corner), within `reach` metres.
Opening openingAcross(const BoundQuery& q, const DiffractionEdge& e, const glm::vec3& B,
                      const glm::vec3& T, float reach) {
  const glm::vec3 out = square(T - B, e.direction);
  if (!(glm::length(out) > 0.f)) return {};
  const glm::vec3 u = glm::normalize(out);
  const std::array<glm::vec3, 2> faces = faceDirections(e);
  const glm::vec3 away = square(-(faces[0] + faces[1]), u);
  if (glm::length(away) < 1e-3f) return {};
  return openingAlong(q, e, B, u, glm::normalize(away), reach);
}

/// Whether channel p's opening at a mouth (its slit without depth: widenOpenChannel) is the
/// one beside point B on edge e: p's edge parallel to e, B on its front or back edge's line (a
/// leaf's top channel ends at the rim's corner, on the rim's line, but is not the rim's opening).
bool mouthOf(const EdgePath& p, const DiffractionEdge& e, const glm::vec3& B) {
  if (p.through == glm::vec3(0.f) || p.slit.depth != 0.0) return false;
  if (std::abs(glm::dot(p.edge->direction, e.direction)) < kParallelEdges) return false;
  const glm::vec3 front = square(B - p.edge->a, e.direction);
  return glm::length(front) < kOnEdge ||
         glm::length(front - square(p.through, e.direction)) < kOnEdge;
}

/// Whether first-order path p's slit is opening o beside point B on edge e: parallel, B along
/// p's edge, the centre lines within half the two widths, and p's edge or its gap's far side on
/// the body o meets (the jamb's path, whose probe met the leaf, and the leaf's rim, whose fan met
/// the wall).
bool sameOpening(const BoundQuery& q, const EdgePath& p, const DiffractionEdge& e,
                 const glm::vec3& B, const Opening& o) {
  const DiffractionEdge& f = *p.edge;
  const float t = glm::dot(B - f.a, f.direction);
  const glm::vec3 centre = B + 0.5f * o.width * o.mouth;
  return std::abs(glm::dot(f.direction, e.direction)) >= kParallelEdges && t >= -kOnEdge &&
         t <= f.length + kOnEdge &&
         glm::length(square(p.slitCentre - centre, e.direction)) <=
             0.5f * (p.gapWidth + o.width) + kOnEdge &&
         (onEdgeBody(q.bodies.body, f, o.surface) || sameBody(q.bodies.body, p.gapCloser, o.surface));
}

/// The path whose slit is this opening, its owner or not (which owns it is settled after): a
/// first-order path's (sameOpening), or a channel's open at the mouth beside B (a box leaf's
/// latch face ajar, its back rim's path a moving object's). A channel's slit with depth is not
/// it: the reveal's beside a sheet leaf proud of the wall is deeper and narrower than the rim's
/// opening.
const EdgePath* carrierOf(const BoundQuery& q, const DiffractionEdge& e, const glm::vec3& B,
                          const Opening& o, const std::vector<EdgePath>& paths,
                          const EdgePath* self = nullptr) {
  for (const EdgePath& p : paths)
    if (&p != self && p.gapWidth > 0.f &&
        (p.through == glm::vec3(0.f) ? sameOpening(q, p, e, B, o) : mouthOf(p, e, B)))
      return &p;
  return nullptr;
}

/// Makes p (over its edge, at its point) the path through opening o: its own slit, without
/// depth, along the edge's extent.
void throughOpening(const Opening& o, const glm::vec3& source, const glm::vec3& L, EdgePath& p) {
  p.mouth = o.mouth;
  slitAlongEdge(o.width, source, L, p);
}

/// The length (m) of chain c's way from `from` (the source or L) to its point n, less the
/// straight line: the detour round its other edges before the opening at n.
float detour(const EdgeChain& c, const glm::vec3& from, size_t n, bool fromSource) {
  float length = 0.f;
  glm::vec3 last = from;
  for (size_t k = 0; k < c.n; ++k) {
    const size_t i = fromSource ? k : c.n - 1 - k;
    length += glm::distance(last, c.q[i]);
    last = c.q[i];
    if (i == n) break;
  }
  return std::max(0.f, length - glm::distance(from, c.q[n]));
}

/// The opening's own slit path beside chain c's point n on its edge e: its legs straight to
/// the slit's centre line, the chain's detour round its other edges on each side added to the
/// leg on that side, with a screen's shadow loss for it; no UTD field (the chain keeps its own,
/// 1 - s of its pressure). Summed with the other paths in pressure: the slits round a leaf are
/// in phase at low frequencies (added in energy, a leaf ajar 5 degrees in a sheet wall read 2.7
/// dB below shut, 3.5 dB below the slit model of its openings).
EdgePath openingPath(const EdgeChain& c, size_t n, const DiffractionEdge& e, const Opening& o,
                     const BoundQuery& q) {
  EdgePath p{};
  p.edge = &e;
  p.q = c.q[n];
  p.lipLength[0] = p.lipExcess[0] = detour(c, q.source, n, true);
  p.lipLength[1] = p.lipExcess[1] = detour(c, q.L, n, false);
  throughOpening(o, q.source, q.L, p);
  p.slitOwner = true;
  p.gapCloser = o.surface;
  p.share = 0.0;
  p.atEnd = true;
  p.phaseSpread = o.width;
  p.length = p.slit.r + p.slit.s;
  p.legs = float(p.length);
  // The way leaves the source toward the chain's first edge where it detours round the chain
  // before the opening, and reaches L from its last edge where it detours after it.
  p.leaving = glm::normalize((n > 0 ? c.q[0] : p.slitCentre) - q.source);
  p.arrival = glm::normalize((n + 1 < c.n ? c.q[c.n - 1] : p.slitCentre) - q.L);
  return p;
}

/// The opening beside edge e at B for the leg toward `toward` (from `from`) within the partner
/// reach, else the one for the leg the other way: the first that is a slit's (within the slit
/// reach), else the first found.
Opening openingFor(const BoundQuery& q, const DiffractionEdge& e, const glm::vec3& B,
                   const glm::vec3& from, const glm::vec3& toward) {
  const Opening ahead = openingAt(q, e, B, from, toward, partnerReach(e));
  if (ahead.width > 0.f && ahead.width <= slitReach(e)) return ahead;
  const Opening behind = openingAt(q, e, B, toward, from, partnerReach(e));
  if (behind.width > 0.f && (behind.width <= slitReach(e) || ahead.width == 0.f)) return behind;
  return ahead;
}

/// A chain's opening: the edge it lies beside (one of the chain's ends), the chain's point
/// there, the opening, and the path that carries its slit (null: none yet).
struct ChainOpening {
  const DiffractionEdge* edge = nullptr;
  size_t n = 0;
  Opening o;
  const EdgePath* carrier = nullptr;
};

/// Chain c's opening at its last edge (toward L), else at its first (toward the source): the
/// first carried by a path in `paths`, or within the slit reach; none (edge null) else.
ChainOpening chainOpening(const EdgeChain& c, const std::vector<EdgePath>& paths,
                          const BoundQuery& q) {
  const bool one = c.n == 1;
  for (size_t end = 0; end < 2; ++end) {
    const DiffractionEdge& e = c.ends[1 - end];
    const size_t n = end == 0 ? c.n - 1 : 0;
    if (!smallEdge(q, e)) continue;
    const Opening o = end == 0 ? openingAt(q, e, c.q[n], one ? q.source : c.q[n - 1], q.L,
                                           partnerReach(e))
                               : openingAt(q, e, c.q[n], one ? q.L : c.q[1], q.source,
                                           partnerReach(e));
    if (o.width == 0.f) continue;
    const EdgePath* carrier = carrierOf(q, e, c.q[n], o, paths);
    if (carrier || o.width <= slitReach(e)) return {&e, n, o, carrier};
  }
  return {};
}

/// The opening chain c's gap leg (EdgeChain::gapLeg) threads between a small body and a large
/// one (a leaf's rim and the wall's jamb): beside the leg's end on the small body's edge, the
/// fan looking along the leg away from that body (openingAcross), within the slit reach; the
/// path that carries it, if one does. None (edge null) where it finds none, or the leg runs
/// between two small bodies (the slot between two posts of a row, which the posts' own paths
/// and floors carry).
ChainOpening gapOpening(const EdgeChain& c, const std::vector<EdgePath>& paths,
                        const BoundQuery& q) {
  const size_t k = c.gapLeg;
  for (size_t end = 0; end < 2; ++end) {
    const DiffractionEdge& e = c.gapEnds[1 - end];
    const size_t n = end == 0 ? k : k - 1, other = end == 0 ? k - 1 : k;
    if (!smallEdge(q, e) || smallEdge(q, c.gapEnds[end])) continue;
    const Opening o = openingAcross(q, e, c.q[n], c.q[other], slitReach(e));
    if (o.width == 0.f) continue;
    return {&e, n, o, carrierOf(q, e, c.q[n], o, paths)};
  }
  return {};
}

/// Whether path p is looked at by openFreeEdges: a first-order path over a small body's edge
/// (a moving object's rim among them) with its UTD field.
bool looksForOpening(const EdgePath& p, const BoundQuery& q) {
  return !p.atEnd && p.through == glm::vec3(0.f) && p.share > 0.0 && smallEdge(q, *p.edge);
}

/// Whether opening o replaces p's slit: p has none, or one too short along its edge for the
/// slit model, or one kNarrowerOpening times as wide as o or more (the probe, square to the
/// edge, met a surface farther off than the one the path passes at a slant), or one closed by
/// the body o meets (the same opening, which the probe measures as the source or the listener
/// sees it: a leaf's rim ajar 10-20 degrees and the wall past the jamb, 4 cm against 16 cm
/// apart, the probe stopped by the reveal's plane, the fan by the wall's face).
bool replacesSlit(const EdgePath& p, const Opening& o, const BoundQuery& q) {
  constexpr float kNarrowerOpening = 1.1f;
  return !(p.gapWidth > 0.f) || p.slitAspect < kSlitMinAspect ||
         p.gapWidth >= kNarrowerOpening * o.width ||
         sameBody(q.bodies.body, p.gapCloser, o.surface);
}

/// A channel along a small body's face with nothing across it (its slit without depth:
/// engine/path_slits.cpp findSlits) passes the opening at one of its mouths: a leaf ajar 4-20
/// degrees, between its latch end's back rim and the jamb's corner, 1 to 25 cm apart. The gap
/// probe measures it square to the face and finds what the listener sees of it, a quarter to a
/// third of it; the slit is as wide as the opening (Gomperts's slit width, the narrowest
/// section the sound passes). Widened where the opening ahead of the back mouth (toward the
/// listener), else ahead of the front one, is wider than the probe's width.
void widenOpenChannel(EdgePath& p, const BoundQuery& q) {
  if (p.through == glm::vec3(0.f) || !(p.gapWidth > 0.f) || p.slit.depth != 0.0) return;
  DiffractionEdge back = *p.edge;
  back.a += p.through;
  back.b += p.through;
  Opening o = openingAt(q, back, p.q + p.through, p.q, q.L, slitReach(back));
  if (o.width == 0.f) o = openingAt(q, *p.edge, p.q, p.q + p.through, q.source, slitReach(back));
  if (!(o.width > p.gapWidth)) return;
  p.gapWidth = o.width;
  p.slit.width = double(o.width);
  p.slitAspect = std::min(p.slitAspect, double(p.edge->length) / double(o.width));
}

/// Frees the paths that took p's slit as its other side (markSlitPartners), before p's slit is
/// replaced: they are free edges again, and may be the new slit's other side.
void releasePartners(const EdgePath& p, std::vector<EdgePath>& paths) {
  if (!(p.gapWidth > 0.f) || !p.slitOwner) return;
  for (EdgePath& r : paths)
    if (&r != &p && !r.slitOwner && r.through == glm::vec3(0.f) && r.gapWidth > 0.f &&
        r.slitCentre == p.slitCentre)
      r.gapWidth = 0.f;
}

}  // namespace

bool hasOpening(const EdgePath& p, const BoundQuery& q, const std::vector<EdgePath>& paths) {
  const Opening o = openingFor(q, *p.edge, p.q, q.source, q.L);
  return o.width > 0.f && (o.width <= slitReach(*p.edge) || carrierOf(q, *p.edge, p.q, o, paths));
}

void openFreeEdges(std::vector<EdgePath>& paths, const BoundQuery& q) {
  for (EdgePath& p : paths) widenOpenChannel(p, q);
  for (EdgePath& p : paths) {
    if (!looksForOpening(p, q)) continue;
    const Opening o = openingFor(q, *p.edge, p.q, q.source, q.L);
    if (o.width == 0.f || !replacesSlit(p, o, q)) continue;
    const EdgePath* carrier = carrierOf(q, *p.edge, p.q, o, paths, &p);
    if (!carrier && o.width > slitReach(*p.edge)) continue;  // too wide for a slit of its own
    releasePartners(p, paths);
    if (carrier) {
      takeSlit(p, *carrier);
      continue;
    }
    throughOpening(o, q.source, q.L, p);
    p.slitOwner = true;
    p.gapCloser = o.surface;
  }
}

bool openChannel(EdgePath& p, const BoundQuery& q, float widest,
                 const std::vector<EdgePath>& paths) {
  if (p.through == glm::vec3(0.f) || !smallEdge(q, *p.edge)) return false;
  const glm::vec3 beyond = p.beyond + p.lipBeyond, before = p.before + p.lipBefore;
  const bool out = beyond != glm::vec3(0.f);
  if (out == (before != glm::vec3(0.f))) return false;
  DiffractionEdge back = *p.edge;
  back.a += p.through;
  back.b += p.through;
  const glm::vec3 B = p.q + p.through;
  const Opening o = out ? openingAt(q, back, B, p.q, B + beyond, slitReach(back))
                        : openingAt(q, *p.edge, p.q, B, p.q - before, slitReach(*p.edge));
  if (!(o.width > 0.f) || o.width > widest || o.surface >= q.bodies.body.size() ||
      !largeBody(q.bodies, o.surface) || carrierOf(q, out ? back : *p.edge, out ? B : p.q, o, paths))
    return false;
  p.gapCloser = o.surface;
  slitAlongEdge(o.width, q.source + before, q.L - p.through - beyond, p);
  p.slit.depth = 0.0;
  return true;
}

void addChainOpenings(std::vector<EdgeChain>& chains, std::vector<EdgePath>& paths,
                      const BoundQuery& q) {
  std::erase_if(chains, [&](EdgeChain& c) {
    if (c.gapLeg == 0) return false;
    const ChainOpening o = gapOpening(c, paths, q);
    if (!o.edge || o.carrier) return true;  // no opening, or a path carries it: no chain
    paths.push_back(openingPath(c, o.n, *o.edge, o.o, q));
    c.opening = int32_t(paths.size() - 1);
    return false;
  });
  for (EdgeChain& c : chains) {
    if (c.gapLeg != 0) continue;
    c.opening = -1;
    const EdgePath* carrier = channelOf(c, paths);
    const ChainOpening o = carrier ? ChainOpening{} : chainOpening(c, paths, q);
    if (!carrier) carrier = o.carrier;
    if (carrier) {
      c.opening = int32_t(carrier - paths.data());
    } else if (o.edge) {
      paths.push_back(openingPath(c, o.n, *o.edge, o.o, q));
      c.opening = int32_t(paths.size() - 1);
    }
  }
}

std::vector<Bands> chainUnslit(const std::vector<EdgeChain>& chains,
                               const std::vector<EdgePath>& paths, float speedOfSound) {
  std::vector<Bands> out(chains.size(), Bands(1.f));
  for (size_t c = 0; c < chains.size(); ++c)
    if (chains[c].opening >= 0) out[c] = unslitShare(paths[size_t(chains[c].opening)], speedOfSound);
  return out;
}

}  // namespace dpc
