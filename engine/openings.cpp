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

/// Whether flat surface s is on the body of edge e's faces (its own solid: a door stop's lip
/// face seen from its back corner). Moving objects' surfaces are not told apart from each
/// other: an object's edge takes any object's surface for its own.
bool sameBody(const BoundQuery& q, const DiffractionEdge& e, uint32_t s) {
  const std::vector<uint32_t>& body = q.bodies.body;
  if (s == kMovingObjects) return e.surfaces[0] == kMovingObjects;
  if (s >= body.size()) return false;
  for (uint32_t f : e.surfaces)
    if (f < body.size() && body[f] == body[s]) return true;
  return false;
}

/// The opening beside edge e at its chain point B, for the leg from B toward T, the chain
/// arriving from A (the chain turns round e's solid toward that side; the fan looks the other
/// way). Width 0: none within reach.
Opening openingAt(const BoundQuery& q, const DiffractionEdge& e, const glm::vec3& B,
                  const glm::vec3& A, const glm::vec3& T) {
  const glm::vec3 out = square(T - B, e.direction), in = square(B - A, e.direction);
  if (!(glm::length(out) > 0.f) || !(glm::length(in) > 0.f)) return {};
  const glm::vec3 u = glm::normalize(out);
  const glm::vec3 turn = square(u - glm::normalize(in), u);
  if (glm::length(turn) < 1e-3f) return {};  // no turn: no side to look at
  const glm::vec3 v = -glm::normalize(turn);
  const float reach = std::min(kOpeningReach, e.length / float(kSlitMinAspect));
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
        sameBody(q, e, surfaceOf(q.surfaces, hits[i].surface.triangle)))
      continue;
    const glm::vec3 across = square(hits[i].surface.t * rays[i].dir, e.direction);
    if (const float w = glm::length(across); w > 0.f && (o.width == 0.f || w < o.width))
      o = {w, across / w, hits[i].surface.triangle};
  }
  return o;
}

/// The path whose slit is this opening (parallel, its centre line within the wider of the two
/// widths of the opening's): a channel's or an edge path's found by the probe.
const EdgePath* carrierOf(const DiffractionEdge& e, const glm::vec3& B, const Opening& o,
                          const std::vector<EdgePath>& paths, const EdgePath* self = nullptr) {
  const glm::vec3 centre = B + 0.5f * o.width * o.mouth;
  for (const EdgePath& p : paths)
    if (&p != self && p.gapWidth > 0.f && p.slitOwner &&
        std::abs(glm::dot(p.edge->direction, e.direction)) >= kParallelEdges &&
        glm::length(square(p.slitCentre - centre, e.direction)) <= std::max(p.gapWidth, o.width))
      return &p;
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
  Opening o = openingAt(q, *e, B, one ? q.source : c.q[c.n - 2], q.L);
  if (o.width == 0.f) {
    e = &c.ends[0];
    B = c.q[0];
    o = openingAt(q, *e, B, one ? q.L : c.q[1], q.source);
  }
  if (o.width == 0.f) return {};
  if (const EdgePath* carrier = carrierOf(*e, B, o, paths))
    return {unslitShare(*carrier, q.speedOfSound), Bands(0.f)};
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
/// edge, met a surface farther off than the one the path passes at a slant).
bool narrowerThanSlit(const EdgePath& p, const Opening& o) {
  constexpr float kNarrowerOpening = 1.1f;
  return !(p.gapWidth > 0.f) || p.slitAspect < kSlitMinAspect ||
         p.gapWidth >= kNarrowerOpening * o.width;
}

}  // namespace

void openFreeEdges(std::vector<EdgePath>& paths, const BoundQuery& q) {
  for (EdgePath& p : paths) {
    if (!looksForOpening(p, q)) continue;
    Opening o = openingAt(q, *p.edge, p.q, q.source, q.L);
    if (o.width == 0.f) o = openingAt(q, *p.edge, p.q, q.L, q.source);
    if (o.width == 0.f || !narrowerThanSlit(p, o)) continue;
    if (const EdgePath* carrier = carrierOf(*p.edge, p.q, o, paths, &p)) {
      p.gapWidth = carrier->gapWidth;
      p.slit = carrier->slit;
      p.slitCentre = carrier->slitCentre;
      p.slitAspect = carrier->slitAspect;
      p.gapCloser = carrier->edge->surfaces[0];
      p.slitOwner = false;
      continue;
    }
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
