#include "engine/edge_path.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/geometric.hpp>
#include <numbers>

namespace dpc {

namespace {

constexpr double kPi = std::numbers::pi;

}  // namespace

double faceAngle(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& p) {
  const glm::vec3 v = p - q;
  const double a = std::atan2(double(glm::dot(v, e.normal0)), double(glm::dot(v, e.face0)));
  return a < 0 ? a + 2.0 * kPi : a;
}

bool withinEdge(const DiffractionEdge& e, const glm::vec3& x) {
  const float t = glm::dot(x - e.a, e.direction);
  return t > 0.f && t < e.length;
}

bool airWedge(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& source,
              const glm::vec3& other, double& phiS, double& phiOther, double& wedge,
              double& sense) {
  phiS = faceAngle(e, q, source);
  phiOther = faceAngle(e, q, other);
  // The source's wedge is the air wedge: [0, open] or, measured from face 0 the other way,
  // [0, 2 pi - open].
  wedge = double(e.open);
  sense = 1.0;
  if (phiS > wedge) {
    sense = -1.0;
    wedge = 2.0 * kPi - wedge;
    phiS = 2.0 * kPi - phiS;
    phiOther = 2.0 * kPi - phiOther;
  }
  return phiOther > 0.0 && phiOther < wedge && wedge > kConvexWedge;
}

namespace {

/// Angles of the source and the listener seen from Q in the air wedge (airWedge); false unless
/// the listener is in the source's wedge and that wedge is wider than about pi (narrower ones
/// cannot shadow: a room's inner corner seen from inside).
bool wedgeAngles(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& source,
                 const glm::vec3& L, bool directVisible, double& phiS, double& phiL, double& wedge,
                 double& sense) {
  if (!airWedge(e, q, source, L, phiS, phiL, wedge, sense)) return false;
  // On the shadow boundary itself (|phi - phi'| = pi) the occlusion test that decided
  // direct.visible and the UTD's side of the boundary could disagree by rounding; put the
  // listener 1e-4 rad on the side the direct sound's visibility says.
  constexpr double kBoundary = 1e-4;
  const double dphi = phiL - phiS;
  if (std::abs(std::abs(dphi) - kPi) < kBoundary)
    phiL = phiS + std::copysign(directVisible ? kPi - kBoundary : kPi + kBoundary, dphi);
  return true;
}

/// Per face (0 at angle 0, 1 at `wedge`), whether its reflection zone as UTD takes the face
/// (without end) holds the listener: the listener sees the source's image in its plane. On the
/// boundary itself (a listener on the axis of a symmetric doorway, seen by both edges of a
/// reveal at their boundaries) it counts as inside, so that both edges decide alike.
std::array<bool, 2> reflectionZones(double phiS, double phiL, double wedge) {
  constexpr double kOnBoundary = 1e-6;  // rad, single-precision geometry
  const bool face0 = phiS < kPi && phiL < kPi - phiS + kOnBoundary;
  const bool faceN = phiS > wedge - kPi && phiL > 2.0 * wedge - kPi - phiS - kOnBoundary;
  return {face0, faceN};
}

/// Zeroes the reflection-boundary terms of the faces whose reflection zone holds the listener
/// and that are there to reflect (EdgePath::reflects).
/// There the face's specular reflection reaches the listener, and it is the tracer's (an image
/// source or a ray path, added in energy), not the coherent sum's; the term that corrects that
/// reflection near its boundary (about -1/2 of it just inside) would stand alone and subtract
/// half a reflection the sum never held. In a doorway through a 0.3 m wall, with the line of
/// sight along its reveals, the six edges' such terms put the direct sound 11 dB above the
/// free field in every band. Outside the zone the term is the diffraction of the face's image
/// source, and kept. Faces: face 0 at angle 0, face n at `wedge`; terms as utdWedgeTerms orders
/// them ([2] singular at face n's boundary, [3] at face 0's).
void dropTracedReflectionTerms(const std::array<bool, 2>& zones,
                               const std::array<bool, 2>& reflects, std::array<UtdTerm, 4>& terms) {
  if (zones[0] && reflects[0]) terms[3].cot = 0.0;
  if (zones[1] && reflects[1]) terms[2].cot = 0.0;
}

/// Zeroes the shadow-boundary terms when the listener lies in the shadow of the edge's
/// half-plane or wedge as UTD takes it (faces without end) while the line of sight is free: the
/// face ends before the line of sight (the leaf of a door ajar, seen past its free edge). Those
/// terms continue the incident field into that shadow at about half its amplitude, and beside
/// the direct sound, which is there, they added it again: a leaf ajar 80° read 11 dB above the
/// open doorway at 63 Hz. Terms as utdWedgeTerms orders them ([0] and [1]: phi - phiSource).
void dropAbsentShadowTerms(double phiS, double phiL, bool directVisible,
                           std::array<UtdTerm, 4>& terms) {
  if (!directVisible || !(std::abs(phiL - phiS) > kPi)) return;
  terms[0].cot = 0.0;
  terms[1].cot = 0.0;
}

/// The unit direction from Q across the mouth of a gap the path may pass, in the plane
/// perpendicular to the edge, away from the edge's solid: for a sheet's rim the sheet's own
/// continuation (-face0); for a wedge the middle of the angles around the edge that both the
/// source and the listener see (from the source at phiS, the wedge hides the angles beyond
/// phiS +- pi), which a lone wedge never closes.
glm::vec3 mouthDirection(const DiffractionEdge& e, double phiS, double phiL, double wedge,
                         double sense) {
  if (isFreeEdge(e)) return -e.face0;
  const double lo = std::max({0.0, phiS - kPi, phiL - kPi});
  const double hi = std::min({wedge, phiS + kPi, phiL + kPi});
  const double mid = 0.5 * (lo + hi);
  return float(std::cos(mid)) * e.face0 + float(sense * std::sin(mid)) * e.normal0;
}

/// The path's parts through point q on e's line (its length, UTD parameters, angles, terms,
/// legs' directions; p.q = q): false when a leg is too short or the wedge cannot diffract.
bool edgeFields(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& source,
                const glm::vec3& L, bool directVisible, EdgePath& p) {
  const glm::vec3 toQ = q - source, toL = L - q;
  const float r = glm::length(toQ), s = glm::length(toL);
  if (!(r > kLegEpsilon && s > kLegEpsilon)) return false;
  double phiS = 0.0, phiL = 0.0, wedge = 0.0, sense = 1.0;
  if (!wedgeAngles(e, q, source, L, directVisible, phiS, phiL, wedge, sense)) return false;
  const double sinB = double(glm::length(glm::cross(toQ / r, e.direction)));
  p.length = double(r) + double(s);
  p.distanceParameter = double(r) * double(s) * sinB * sinB / p.length;
  p.spreading = 1.0 / double(r) * std::sqrt(double(r) / (double(s) * p.length));
  p.prefactor = utdPrefactor(wedge / kPi, sinB);
  p.phiS = phiS;
  p.phiL = phiL;
  p.wedge = wedge;
  setTerms(directVisible, p);
  p.legs = r + s;
  p.arrival = -toL / s;
  p.leaving = toQ / r;
  p.edge = &e;
  p.q = q;
  p.mouth = mouthDirection(e, phiS, phiL, wedge, sense);
  p.turn = float(sense) * e.normal0;
  p.airWedge = float(wedge);
  return true;
}

/// rad/m: the lowest (band 0) or highest (the last band) frequency a band's coherent sum is
/// evaluated at (diffractionFrequencyHz), at the default speed of sound (PropagationSettings):
/// cornerPath's reach is measured there.
double cornerWavenumber(int band) {
  const int i = band == 0 ? 0 : kDiffractionFrequenciesPerBand - 1;
  return 2.0 * kPi * diffractionFrequencyHz(band, i) / double(PropagationSettings{}.speedOfSound);
}

}  // namespace

std::array<glm::vec3, 2> faceDirections(const DiffractionEdge& e) {
  return {e.face0, std::cos(e.open) * e.face0 + std::sin(e.open) * e.normal0};
}

bool joinedByFace(const DiffractionEdge& a, const DiffractionEdge& b) {
  constexpr float kParallel = 0.999f;
  if (std::abs(glm::dot(a.direction, b.direction)) < kParallel) return false;
  const glm::vec3 v = b.a - a.a;
  const glm::vec3 across = v - glm::dot(v, a.direction) * a.direction;
  const float d = glm::length(across);
  if (!(d > 1e-3f)) return false;
  const glm::vec3 u = across / d;
  auto along = [](const std::array<glm::vec3, 2>& faces, const glm::vec3& w) {
    return glm::dot(faces[0], w) > kParallel || glm::dot(faces[1], w) > kParallel;
  };
  return along(faceDirections(a), u) && along(faceDirections(b), -u);
}

void setTerms(bool directVisible, EdgePath& p) {
  p.terms = utdWedgeTerms(p.wedge / kPi, p.phiL, p.phiS);
  dropTracedReflectionTerms(reflectionZones(p.phiS, p.phiL, p.wedge), p.reflects, p.terms);
  // A corner path's run excludes Q, where a term continues the incident field (below).
  if (!p.corner) dropAbsentShadowTerms(p.phiS, p.phiL, directVisible, p.terms);
  p.sums = utdTermSums(p.terms);
}

bool cornerPath(const DiffractionEdge& e, const glm::vec3& source, const glm::vec3& L,
                bool directVisible, EdgePath& p) {
  constexpr float kHeld = 1e-4f;  // m: this edge holds its run's end
  if (!e.freeEnds) return false;
  const glm::vec3 ps = source - e.a, pl = L - e.a;
  const float ts = glm::dot(ps, e.direction), tl = glm::dot(pl, e.direction);
  const float rs = glm::length(ps - ts * e.direction), rl = glm::length(pl - tl * e.direction);
  if (!(rs > 1e-4f) || !(rl > 1e-4f)) return false;
  const float t = ts + (tl - ts) * rs / (rs + rl);
  const bool pastB = t > e.runTo && e.runTo <= e.length + kHeld;
  const bool pastA = t < e.runFrom && e.runFrom >= -kHeld;
  if (!std::isfinite(t) || (!pastA && !pastB)) return false;
  // The reach, before the fields: the along-edge curvature sin^2 beta (r + s) / (2 r s).
  const glm::vec3 q = e.a + t * e.direction;
  const double r0 = double(glm::distance(source, q)), s0 = double(glm::distance(q, L));
  const double zone = 0.5 * double(rs * rs) / (r0 * r0) * (r0 + s0) / (r0 * s0);
  const double near = pastB ? double(t - e.runTo) : double(e.runFrom - t);
  const double span = double(e.runTo - e.runFrom);
  if (!(near * std::sqrt(cornerWavenumber(0) * zone) < kCornerReach)) return false;
  // A run shorter than a twentieth of a Fresnel unit at the highest frequency (a marker's
  // centimetre seen from 30 m) holds nothing worth its two leg rays.
  if (!(span * std::sqrt(cornerWavenumber(kNumBands - 1) * zone) > 0.05)) return false;
  p.corner = true;
  if (!edgeFields(e, q, source, L, directVisible, p)) return false;
  p.ends = edgeEnds(e, q, source, L, p.phiS, p.phiL, p.wedge, p.terms);
  p.ends.outside = true;
  const float margin = std::min(kEndMargin, 0.01f * e.length);
  p.q = pastB ? e.b - margin * e.direction : e.a + margin * e.direction;
  const float r = glm::distance(source, p.q), s = glm::distance(p.q, L);
  p.legs = r + s;
  p.arrival = (p.q - L) / s;
  p.leaving = (p.q - source) / r;
  return true;
}

bool edgePath(const DiffractionEdge& e, const glm::vec3& source, const glm::vec3& L,
              bool directVisible, EdgePath& p, bool atEnd) {
  // Stationary point: unfold both points about the edge; Q divides the along-edge
  // separation in the ratio of their distances from the edge line.
  const glm::vec3 ps = source - e.a, pl = L - e.a;
  const float ts = glm::dot(ps, e.direction), tl = glm::dot(pl, e.direction);
  const float rs = glm::length(ps - ts * e.direction), rl = glm::length(pl - tl * e.direction);
  if (!(rs > 1e-4f) || !(rl > 1e-4f)) return false;
  float t = ts + (tl - ts) * rs / (rs + rl);
  const bool inside = t > 0.f && t < e.length;
  if (inside == atEnd || !std::isfinite(t)) return false;
  if (atEnd) {
    const float margin = std::min(kEndMargin, 0.01f * e.length);
    t = std::clamp(t, margin, e.length - margin);
    p.atEnd = true;
    p.share = 0.0;
  }
  const glm::vec3 q = e.a + t * e.direction;
  if (!edgeFields(e, q, source, L, directVisible, p)) return false;
  if (!atEnd) p.ends = edgeEnds(e, q, source, L, p.phiS, p.phiL, p.wedge, p.terms);
  return true;
}

std::array<TraceRay, 2> legRays(const glm::vec3& source, const glm::vec3& L, const EdgePath& p) {
  const glm::vec3 front = p.q - p.before - p.lipBefore;
  const glm::vec3 back = p.q + p.through + p.beyond + p.lipBeyond;
  const float r = glm::distance(source, front), b = glm::distance(back, L);
  return {TraceRay{source, (front - source) / r, kLegEpsilon, r - kLegEpsilon},
          TraceRay{back, (L - back) / b, kLegEpsilon, b - kLegEpsilon}};
}

void findAbsentReflections(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L,
                           bool directVisible, EdgePath& p) {
  constexpr float kIntoFace = 1e-3f, kProbe = 1e-3f, kOnFarEdge = 1e-5f;  // m
  const std::array<bool, 2> zones = reflectionZones(p.phiS, p.phiL, p.wedge);
  if (!p.edge || p.corner || p.atEnd || !(zones[0] || zones[1])) return;
  const DiffractionEdge& e = *p.edge;
  const std::array<glm::vec3, 2> faces = faceDirections(e);
  for (size_t f = 0; f < 2; ++f) {
    if (!zones[f]) continue;
    const glm::vec3 n = glm::normalize(glm::cross(e.direction, faces[f]));
    const float ds = glm::dot(source - p.q, n), dl = glm::dot(L - p.q, n);
    if (!(ds * dl > 0.f)) continue;  // not both on one side of its plane: no image to see
    const glm::vec3 mirrored = L - 2.f * dl * n;
    glm::vec3 at = source + (ds / (ds + dl)) * (mirrored - source);
    const float along = glm::dot(at - p.q, faces[f]);
    if (along < kIntoFace) at += (kIntoFace - along) * faces[f];  // next to its edge it is there
    const glm::vec3 side = ds > 0.f ? n : -n;
    auto holds = [&](const glm::vec3& x) {
      return tracer.occluded(TraceRay{x + kProbe * side, -side, 0.f, 2.f * kProbe});
    };
    // A point on the face's far edge itself counts as on the face, as the far edge's own zone
    // counts its boundary as inside, so that both edges decide alike.
    p.reflects[f] = holds(at) || holds(at - kOnFarEdge * faces[f]);
  }
  if (p.reflects[0] && p.reflects[1]) return;
  setTerms(directVisible, p);
  p.ends = edgeEnds(e, p.q, source, L, p.phiS, p.phiL, p.wedge, p.terms);
}

bool legsFree(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L,
              const EdgePath& p) {
  const std::array<TraceRay, 2> legs = legRays(source, L, p);
  return !tracer.occluded(legs[0]) && !tracer.occluded(legs[1]);
}

double channelDepth(const EdgePath& p) {
  const double depth = double(glm::length(p.through));
  if (!(depth > 0.0)) return 0.0;
  const glm::vec3 m = p.through / float(depth);
  auto squareLeg = [&](const glm::vec3& v) {  // along m, then across it
    const float along = glm::dot(v, m);
    return double(std::abs(along)) + double(glm::length(v - along * m));
  };
  // A narrow leg wider than the slit (the gap between a leaf's face and its stop, opening as
  // the leaf swings) counts its length times the slit's width over its own: at low frequency
  // the channel's parts are masses in series, each its length over its width per unit length.
  auto share = [&](float width) {
    return width > p.gapWidth && p.gapWidth > 0.f ? double(p.gapWidth / width) : 1.0;
  };
  return squareLeg(p.before) * share(p.legWidth[0]) + depth +
         squareLeg(p.beyond) * share(p.legWidth[1]);
}

void makeSlit(const glm::vec3& source, const glm::vec3& L, float from, float to, EdgePath& p) {
  const DiffractionEdge& e = *p.edge;
  // The slit's centre line runs along the edge through Q (a measured channel's Q lies off its
  // edge, where the gap's far side stands), half the width across the mouth.
  const glm::vec3 line = p.q - glm::dot(p.q - e.a, e.direction) * e.direction;
  const glm::vec3 a = line + 0.5f * p.gapWidth * p.mouth;
  const glm::vec3 ps = source - a, pl = L - a;
  const float ts = glm::dot(ps, e.direction), tl = glm::dot(pl, e.direction);
  const float rs = glm::length(ps - ts * e.direction), rl = glm::length(pl - tl * e.direction);
  const float tq = glm::dot(p.q - e.a, e.direction);
  const float stationary = ts + (tl - ts) * rs / std::max(rs + rl, 1e-6f);
  // Beyond the slit's ends, the path is expanded at the nearer end (engine/slit.h).
  const float z0 = std::clamp(stationary, tq + from, tq + to);
  const glm::vec3 c = a + z0 * e.direction, toC = c - source, toL = L - c;
  auto sinFromAxis = [&](const glm::vec3& v) {  // |sin| of v's angle from the slit's axis
    const glm::vec3 across = v - glm::dot(v, e.direction) * e.direction;
    const float l = glm::length(across);
    return l > 0.f ? double(std::abs(glm::dot(across, p.mouth)) / l) : 0.0;
  };
  SlitPath& sp = p.slit;
  // A turned channel's free legs (engine/channel_turn.h) lengthen the legs to the slit.
  sp.r = std::max(double(glm::length(toC)), double(kLegEpsilon)) + double(p.lipLength[0]);
  sp.s = std::max(double(glm::length(toL)), double(kLegEpsilon)) + double(p.lipLength[1]);
  sp.sinBeta = double(glm::length(glm::cross(toC, e.direction))) / sp.r;
  double vertex = double(z0);
  sp.phase = sp.r + sp.s;
  sp.curvature = 0.0;
  if (z0 != stationary) {  // d(r + s)/dz and d2(r + s)/dz2 at the end
    const double cs = double(glm::dot(toC, e.direction)) / sp.r;
    const double cl = -double(glm::dot(toL, e.direction)) / sp.s;
    const double slope = cs + cl, bend = (1.0 - cs * cs) / sp.r + (1.0 - cl * cl) / sp.s;
    if (bend > 1e-9) {
      vertex -= slope / bend;
      sp.phase -= slope * slope / (2.0 * bend);
      sp.curvature = 0.5 * bend;
    }
  }
  sp.zFrom = double(tq + from) - vertex;
  sp.zTo = double(tq + to) - vertex;
  sp.sinSource = sinFromAxis(toC);
  sp.sinListener = sinFromAxis(toL);
  sp.width = double(p.gapWidth);
  sp.depth = channelDepth(p);
  sp.shadowExcess = {double(p.lipExcess[0]), double(p.lipExcess[1])};
  p.slitCentre = c;
}

void slitAlongEdge(float width, const glm::vec3& source, const glm::vec3& L, EdgePath& p) {
  p.gapWidth = width;
  p.slitAspect = std::min(kSlitFullAspect, double(p.edge->length) / double(width));
  const float t = glm::dot(p.q - p.edge->a, p.edge->direction);
  makeSlit(source, L, -t, p.edge->length - t, p);
}

double slitShare(const EdgePath& p, double k) {
  return slitWeight(k * p.slit.sinBeta * p.slit.width, p.slitAspect);
}

void takeSlit(EdgePath& p, const EdgePath& from) {
  p.gapWidth = from.gapWidth;
  p.slit = from.slit;
  p.slitCentre = from.slitCentre;
  p.slitAspect = from.slitAspect;
  p.phaseSpread = from.phaseSpread;
  p.gapCloser = from.edge->surfaces[0];
  p.slitOwner = false;
}

bool sameBody(const std::vector<uint32_t>& body, uint32_t s, uint32_t t) {
  return s == t || (s < body.size() && t < body.size() && body[s] == body[t]);
}

bool onEdgeBody(const std::vector<uint32_t>& body, const DiffractionEdge& e, uint32_t s) {
  return sameBody(body, e.surfaces[0], s) || sameBody(body, e.surfaces[1], s);
}

bool acrossSlit(const EdgePath& o, const EdgePath& p, const std::vector<uint32_t>* body) {
  // Widths from o's point: the probe met p's surface within one width, p's edge within 1.5 more
  // (or, seen at a slant, the legs met p's surface in its shadow short of the opening's width).
  constexpr float kReach = 2.5f;
  auto closes = [&](uint32_t s) {
    return s == o.gapCloser || (body && sameBody(*body, s, o.gapCloser));
  };
  return std::abs(glm::dot(o.edge->direction, p.edge->direction)) >= kParallelEdges &&
         (closes(p.edge->surfaces[0]) || closes(p.edge->surfaces[1])) &&
         glm::dot(p.q - o.q, o.mouth) > 0.f && glm::distance(p.q, o.q) <= kReach * o.gapWidth;
}

namespace {

/// The distance across the edges (perpendicular to o's edge) between o's and p's slit centre
/// lines, each from its slit centre to its back mouth (the centre alone but for a channel), m.
float slitsApart(const EdgePath& o, const EdgePath& p) {
  const glm::vec3 e = o.edge->direction;
  auto flat = [&](const glm::vec3& v) { return v - glm::dot(v, e) * e; };
  auto toSegment = [&](const glm::vec3& x, const glm::vec3& a, const glm::vec3& through) {
    const glm::vec3 d = flat(through), v = flat(x - a);
    const float dd = glm::dot(d, d);
    const float t = dd > 0.f ? std::clamp(glm::dot(v, d) / dd, 0.f, 1.f) : 0.f;
    return glm::length(v - t * d);
  };
  return std::min({toSegment(p.slitCentre, o.slitCentre, o.through),
                   toSegment(p.slitCentre + p.through, o.slitCentre, o.through),
                   toSegment(o.slitCentre, p.slitCentre, p.through),
                   toSegment(o.slitCentre + o.through, p.slitCentre, p.through)});
}

/// True when o's and p's slits (parallel) share part of their extent along o's edge: the top
/// gaps of two leaves meeting in a doorway lie on one line but are two slits.
bool overlapAlong(const EdgePath& o, const EdgePath& p) {
  constexpr float kTolerance = 1e-3f;  // m
  const glm::vec3 d = o.edge->direction;
  auto extent = [&](const EdgePath& x) {
    const float sign = glm::dot(x.edge->direction, d) < 0.f ? -1.f : 1.f;
    const float c = glm::dot(x.slitCentre, d);
    const float a = c + sign * float(x.slit.zFrom), b = c + sign * float(x.slit.zTo);
    return std::pair(std::min(a, b), std::max(a, b));
  };
  const auto [oa, ob] = extent(o);
  const auto [pa, pb] = extent(p);
  return pa < ob - kTolerance && oa < pb - kTolerance;
}

/// True when p, a channel whose far side stands along part of its face, carries the gap that
/// o, an edge's path at its mouth, reads without depth and no narrower: a leaf's latch face
/// half out of the reveal is a slit as deep as the jamb stands along it, while the path round
/// the jamb's corner reads the same gap from the corner, a little wider.
bool channelAtMouth(const EdgePath& p, const EdgePath& o) {
  // Seen along its whole edge: a channel seen along part of it (visibleChannel) would take the
  // slit from o over o's whole extent.
  const bool whole = std::isinf(p.visibleFrom) && std::isinf(p.visibleTo);
  return whole && p.farSideAlong && o.through == glm::vec3(0.f) && !(o.slit.depth > 0.0) &&
         p.gapWidth <= o.gapWidth;
}

}  // namespace

void markSlitOwners(std::vector<EdgePath>& paths, const std::vector<uint32_t>* body) {
  auto sameSlit = [body](const EdgePath& o, const EdgePath& p) {
    return std::abs(glm::dot(o.edge->direction, p.edge->direction)) >= kParallelEdges &&
           overlapAlong(o, p) &&
           (slitsApart(o, p) < 0.5f * std::max(o.gapWidth, p.gapWidth) + 1e-3f ||
            acrossSlit(o, p, body) || acrossSlit(p, o, body));
  };
  // Shallowest first, edges' own paths before channels as deep (the rim's corner of a leaf
  // ajar and the channel along its end face to that corner read one opening; the list holds a
  // moving leaf's channels first and a static one's edges), then in list order: each path owns
  // its slit unless an owner before it in that order finds the same slit, or p is the channel
  // at whose mouth that owner stands.
  std::vector<size_t> order(paths.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  auto channel = [&](size_t k) { return paths[k].through != glm::vec3(0.f); };
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (paths[a].slit.depth != paths[b].slit.depth)
      return paths[a].slit.depth < paths[b].slit.depth;
    return !channel(a) && channel(b);
  });
  for (size_t n = 0; n < order.size(); ++n) {
    EdgePath& p = paths[order[n]];
    p.slitOwner = p.gapWidth > 0.f;
    for (size_t m = 0; m < n && p.slitOwner; ++m) {
      EdgePath& o = paths[order[m]];
      if (!o.slitOwner || !sameSlit(o, p)) continue;
      if (channelAtMouth(p, o))
        o.slitOwner = false;
      else
        p.slitOwner = false;
    }
  }
  // A path that yielded to an owner the channel at its mouth then took the slit from, and that
  // no other owner covers, owns its own again: no slit is left without one.
  for (size_t n = 0; n < order.size(); ++n) {
    EdgePath& p = paths[order[n]];
    if (p.slitOwner || !(p.gapWidth > 0.f)) continue;
    bool covered = false;
    for (size_t m = 0; m < order.size() && !covered; ++m) {
      const EdgePath& o = paths[order[m]];
      covered = m != n && o.slitOwner && (sameSlit(o, p) || sameSlit(p, o));
    }
    p.slitOwner = !covered;
  }
}

void markReveals(const glm::vec3& source, const glm::vec3& L, std::vector<EdgePath>& paths) {
  constexpr float kAlongSight = 0.25f;  // sine of the largest angle, about 14.5 degrees
  const float length = glm::distance(source, L);
  if (!(length > 0.f)) return;
  const glm::vec3 sight = (L - source) / length;
  auto between = [&](const glm::vec3& q) {
    const float t = glm::dot(q - source, sight);
    return t > 0.f && t < length;
  };
  for (size_t k = 0; k < paths.size(); ++k)
    for (size_t j = 0; j < k; ++j) {
      const EdgePath &a = paths[j], &b = paths[k];
      if (a.atEnd || b.atEnd) continue;  // no UTD field to share
      const float apart = glm::distance(a.q, b.q);
      if (!joinedByFace(*a.edge, *b.edge) || !between(a.q) || !between(b.q) || !(apart > 0.f))
        continue;
      if (glm::length(glm::cross((b.q - a.q) / apart, sight)) < kAlongSight)
        paths[j].share = paths[k].share = 0.5;
    }
}

size_t edgeIndex(const std::vector<DiffractionEdge>& edges, const EdgePath& p) {
  const std::less<const DiffractionEdge*> before;
  const DiffractionEdge* first = edges.data();
  return !before(p.edge, first) && before(p.edge, first + edges.size()) ? size_t(p.edge - first)
                                                                        : edges.size();
}

}  // namespace dpc
