#include "engine/openings.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <glm/geometric.hpp>
#include <numbers>

#include "engine/channel_path.h"
#include "engine/diffraction_edges.h"
#include "engine/slit.h"

namespace dpc {

namespace {

constexpr double kPi = std::numbers::pi;

/// m: how far a chain's first point may lie from a channel's front edge to be its route.
constexpr float kOnChannelEdge = 2e-3f;

/// How squarely a surface must face the leg to close an opening across it: |cos| of the angle
/// between its normal and the leg (60 degrees).
constexpr float kFacing = 0.5f;

/// The fan of rays looking for an opening: degrees from the leg, away from the chain's turn.
constexpr std::array<float, 12> kFanDegrees = {5.f,  10.f, 15.f, 20.f, 25.f, 30.f,
                                               35.f, 40.f, 45.f, 50.f, 55.f, 60.f};

/// x with its component along the unit vector d taken out.
glm::vec3 square(const glm::vec3& x, const glm::vec3& d) { return x - glm::dot(x, d) * d; }

/// The open channel (a path along a narrow face whose gap the probe found: engine/channel_path.h)
/// whose route chain c takes, round the face's front edge and across it to the back edge; null
/// when none (a leaf ajar a few degrees: the chain round its latch end's two rims).
const EdgePath* channelOf(const EdgeChain& c, const std::vector<EdgePath>& paths) {
  if (c.n != 2) return nullptr;
  const glm::vec3 step = c.q[1] - c.q[0];
  for (const EdgePath& p : paths) {
    if (!(p.gapWidth > 0.f) || p.through == glm::vec3(0.f)) continue;
    const DiffractionEdge& e = *p.edge;
    const glm::vec3 across = square(step, e.direction);
    const float depth = glm::length(across);
    if (glm::length(square(c.q[0] - e.a, e.direction)) < kOnChannelEdge &&
        depth <= kChannelDepthMax && glm::dot(across, glm::normalize(p.through)) > 0.5f * depth)
      return &p;
  }
  return nullptr;
}

/// The slit model's share s of a slit path of width w (engine/slit.h slitWeight) at the
/// diffraction frequency (band b, i), for sin(beta) and the slit's aspect.
double shareAt(int b, int i, double sinBeta, double width, double aspect, float speedOfSound) {
  const double k = 2.0 * kPi * diffractionFrequencyHz(b, i) / double(speedOfSound);
  return slitWeight(k * sinBeta * width, aspect);
}

/// (1 - s)^2 per band, averaged over its frequencies, for the slit `p` carries.
Bands unslitShare(const EdgePath& p, float speedOfSound) {
  Bands out;
  for (int b = 0; b < kNumBands; ++b) {
    double sum = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const double s = shareAt(b, i, p.slit.sinBeta, p.slit.width, p.slitAspect, speedOfSound);
      sum += (1.0 - s) * (1.0 - s);
    }
    out[b] = float(sum / kDiffractionFrequenciesPerBand);
  }
  return out;
}

/// An opening at a chain's end: its width (m) and the unit direction across it from the edge.
struct Opening {
  float width = 0.f;
  glm::vec3 mouth{0.f};
  uint32_t triangle = 0;  // the Tracer's, of the surface met
};

/// Whether flat surfaces s and t are on one body. Moving objects' surfaces are not told apart
/// from each other (an object's edge takes any object's surface for its own).
bool sameBody(const BoundQuery& q, uint32_t s, uint32_t t) {
  if (s == kMovingObjects || t == kMovingObjects) return s == t;
  const std::vector<uint32_t>& body = q.bodies.body;
  return s < body.size() && t < body.size() && body[s] == body[t];
}

/// Whether flat surface s is on the body of edge e's faces (its own solid: a door stop's lip
/// face seen from its back corner).
bool onEdgeBody(const BoundQuery& q, const DiffractionEdge& e, uint32_t s) {
  return sameBody(q, e.surfaces[0], s) || sameBody(q, e.surfaces[1], s);
}

/// m: how far from edge e a slit's opening is looked for (kOpeningReach, and at least
/// kSlitMinAspect times as long as wide), and a wider one another path's slit may be
/// (kPartnerReach, at least twice as long as wide).
float slitReach(const DiffractionEdge& e) {
  return std::min(kOpeningReach, e.length / float(kSlitMinAspect));
}
float partnerReach(const DiffractionEdge& e) { return std::min(kPartnerReach, 0.5f * e.length); }

/// The opening beside edge e at its chain point B, for the leg from B toward T, the chain
/// arriving from A (the chain turns round e's solid toward that side; the fan looks the other
/// way), within `reach` metres. Width 0: none.
Opening openingAt(const BoundQuery& q, const DiffractionEdge& e, const glm::vec3& B,
                  const glm::vec3& A, const glm::vec3& T, float reach) {
  const glm::vec3 out = square(T - B, e.direction), in = square(B - A, e.direction);
  if (!(glm::length(out) > 0.f) || !(glm::length(in) > 0.f)) return {};
  const glm::vec3 u = glm::normalize(out);
  const glm::vec3 turn = square(u - glm::normalize(in), u);
  if (glm::length(turn) < 1e-3f) return {};  // no turn: no side to look at
  const glm::vec3 v = -glm::normalize(turn);
  std::array<TraceRay, kFanDegrees.size()> rays;
  for (size_t i = 0; i < rays.size(); ++i) {
    const float a = glm::radians(kFanDegrees[i]);
    rays[i] = TraceRay{B, std::cos(a) * u + std::sin(a) * v, surfaceOffset(B), reach};
  }
  std::array<TraceHit, kFanDegrees.size()> hits;
  q.tracer.intersect(rays, hits);
  Opening o;
  for (size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].found) continue;
    // Only a surface ahead of the leg closes an opening across it (a wall's face past a leaf's
    // rim); one the leg runs along and leaves (a reveal beside a door stop's corner) does not.
    const glm::vec3 n = hits[i].surface.normal;
    if (std::abs(glm::dot(n, u)) < kFacing ||
        onEdgeBody(q, e, surfaceOf(q.surfaces, hits[i].surface.triangle)))
      continue;
    const glm::vec3 across = square(hits[i].surface.t * rays[i].dir, e.direction);
    if (const float w = glm::length(across); w > 0.f && (o.width == 0.f || w < o.width))
      o = {w, across / w, hits[i].surface.triangle};
  }
  return o;
}

/// Whether channel p's opening at a mouth (its slit without depth: widenOpenChannel) is the
/// one beside point B: B on its front or back edge's line.
bool mouthOf(const EdgePath& p, const DiffractionEdge& e, const glm::vec3& B) {
  if (p.through == glm::vec3(0.f) || p.slit.depth != 0.0) return false;
  const glm::vec3 front = square(B - p.edge->a, e.direction);
  return glm::length(front) < kOnChannelEdge ||
         glm::length(front - square(p.through, e.direction)) < kOnChannelEdge;
}

/// The path whose slit is this opening, its owner or not (the jamb's and the leaf rim's paths
/// find one slit; which owns it is settled after): a first-order path's parallel slit whose
/// centre line lies within the wider of the two widths of the opening's, or a channel whose
/// opening at a mouth is beside B (a box leaf's latch face ajar: its back rim's path as a
/// moving object's). A channel's slit with depth is not it: the reveal's beside a sheet leaf
/// proud of the wall is deeper and narrower than the rim's opening.
const EdgePath* carrierOf(const DiffractionEdge& e, const glm::vec3& B, const Opening& o,
                          const std::vector<EdgePath>& paths, const EdgePath* self = nullptr) {
  const glm::vec3 centre = B + 0.5f * o.width * o.mouth;
  for (const EdgePath& p : paths) {
    if (&p == self || !(p.gapWidth > 0.f) ||
        std::abs(glm::dot(p.edge->direction, e.direction)) < kParallelEdges)
      continue;
    const float apart = glm::length(square(p.slitCentre - centre, e.direction));
    if (p.through == glm::vec3(0.f) ? apart <= std::max(p.gapWidth, o.width) : mouthOf(p, e, B))
      return &p;
  }
  return nullptr;
}

/// Makes p (over edge e at its point B) the path through opening o: its own slit, without
/// depth, along e's extent.
void throughOpening(const DiffractionEdge& e, const glm::vec3& B, const Opening& o,
                    const glm::vec3& source, const glm::vec3& L, EdgePath& p) {
  p.gapWidth = o.width;
  p.mouth = o.mouth;
  p.slitAspect = std::min(kSlitFullAspect, double(e.length) / double(o.width));
  const float t = glm::dot(B - e.a, e.direction);
  makeSlit(source, L, -t, e.length - t, p);
}

/// The opening's own slit and the chain's share beside it (ChainSlit).
ChainSlit openingSlit(const DiffractionEdge& e, const glm::vec3& B, const Opening& o,
                      const BoundQuery& q, float direct) {
  EdgePath p{};
  p.edge = &e;
  p.q = B;
  throughOpening(e, B, o, q.source, q.L, p);
  ChainSlit out;
  for (int b = 0; b < kNumBands; ++b) {
    const double air =
        std::exp(-double(q.airPerMetre[b]) * (p.slit.r + p.slit.s - double(direct)));
    double own = 0.0, slit = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const double s = shareAt(b, i, p.slit.sinBeta, p.slit.width, p.slitAspect, q.speedOfSound);
      const double k = 2.0 * kPi * diffractionFrequencyHz(b, i) / double(q.speedOfSound);
      own += (1.0 - s) * (1.0 - s);
      slit += s * s * std::norm(slitPressure(p.slit, k)) * double(direct) * double(direct);
    }
    out.unslit[b] = float(own / kDiffractionFrequenciesPerBand);
    out.energy[b] = float(air * slit / kDiffractionFrequenciesPerBand);
  }
  return out;
}

/// Chain c's opening at its last edge (toward L), else at its first (toward the source).
ChainSlit chainSlit(const EdgeChain& c, const std::vector<EdgePath>& paths, const BoundQuery& q,
                    float direct) {
  if (const EdgePath* channel = channelOf(c, paths))
    return {unslitShare(*channel, q.speedOfSound), Bands(0.f)};
  const bool one = c.n == 1;
  const DiffractionEdge* e = &c.ends[1];
  glm::vec3 B = c.q[c.n - 1];
  Opening o = openingAt(q, *e, B, one ? q.source : c.q[c.n - 2], q.L, partnerReach(*e));
  if (o.width == 0.f) {
    e = &c.ends[0];
    B = c.q[0];
    o = openingAt(q, *e, B, one ? q.L : c.q[1], q.source, partnerReach(*e));
  }
  if (o.width == 0.f) return {};
  if (const EdgePath* carrier = carrierOf(*e, B, o, paths))
    return {unslitShare(*carrier, q.speedOfSound), Bands(0.f)};
  if (o.width > slitReach(*e)) return {};  // too wide for a slit of its own
  return openingSlit(*e, B, o, q, direct);
}

/// Whether path p is looked at by openFreeEdges: a first-order path over a small body's edge
/// (a moving object's rim among them) with its UTD field.
bool looksForOpening(const EdgePath& p, const BoundQuery& q) {
  if (p.atEnd || p.through != glm::vec3(0.f) || !(p.share > 0.0)) return false;
  const uint32_t s = p.edge->surfaces[0];
  return s == kMovingObjects || (s < q.bodies.body.size() && !largeBody(q.bodies, s));
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
         sameBody(q, p.gapCloser, surfaceOf(q.surfaces, o.triangle));
}

/// A channel along a small body's face with nothing across it (its slit without depth:
/// engine/diffraction.cpp findSlits) passes the opening at one of its mouths: a leaf ajar 4-20
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

/// The opening beside free path p's edge toward the listener, else toward the source, within
/// `reach` metres.
Opening openingOf(const EdgePath& p, const BoundQuery& q, float reach) {
  const Opening o = openingAt(q, *p.edge, p.q, q.source, q.L, reach);
  return o.width > 0.f ? o : openingAt(q, *p.edge, p.q, q.L, q.source, reach);
}

}  // namespace

bool hasOpening(const EdgePath& p, const BoundQuery& q) {
  return openingOf(p, q, slitReach(*p.edge)).width > 0.f;
}

void openFreeEdges(std::vector<EdgePath>& paths, const BoundQuery& q) {
  for (EdgePath& p : paths) {
    widenOpenChannel(p, q);
    if (!looksForOpening(p, q)) continue;
    const Opening o = openingOf(p, q, partnerReach(*p.edge));
    if (o.width == 0.f || !replacesSlit(p, o, q)) continue;
    if (const EdgePath* carrier = carrierOf(*p.edge, p.q, o, paths, &p)) {
      p.gapWidth = carrier->gapWidth;
      p.slit = carrier->slit;
      p.slitCentre = carrier->slitCentre;
      p.slitAspect = carrier->slitAspect;
      p.gapCloser = carrier->edge->surfaces[0];
      p.slitOwner = false;
      continue;
    }
    if (o.width > slitReach(*p.edge)) continue;  // too wide for a slit of its own
    throughOpening(*p.edge, p.q, o, q.source, q.L, p);
    p.slitOwner = true;
    p.gapCloser = surfaceOf(q.surfaces, o.triangle);
  }
}

std::vector<ChainSlit> chainSlits(const std::vector<EdgeChain>& chains,
                                  const std::vector<EdgePath>& paths, const BoundQuery& q,
                                  float direct) {
  std::vector<ChainSlit> out;
  out.reserve(chains.size());
  for (const EdgeChain& c : chains) out.push_back(chainSlit(c, paths, q, direct));
  return out;
}

}  // namespace dpc
