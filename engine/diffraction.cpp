#include "engine/diffraction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <numbers>

#include "engine/diffraction_edges.h"
#include "engine/gap_probe.h"
#include "engine/slit.h"

namespace dpc {

namespace {

using C = std::complex<double>;
constexpr double kPi = std::numbers::pi;

constexpr float kLegEpsilon = 1e-3f;  // m: keeps occlusion tests off the edge's own faces
constexpr float kGapFarthest = 16.f;  // m: the widest gap probed (k w = 4 pi at 44 Hz)

/// One first-order edge path source -> Q -> listener: its frequency-independent parts, and
/// the slit it passes when its edge bounds a narrow gap.
struct EdgePath {
  double length;                 // r + s, m
  double distanceParameter;      // L = r s sin^2 beta0 / (r + s), m
  double spreading;              // 1/r sqrt(r / (s (r + s))), 1/m
  double prefactor;              // utdPrefactor(n, sin beta0)
  std::array<UtdTerm, 4> terms;  // frequency-independent parts of D
  UtdTermSums sums;              // the terms' asymptotic order sums (utdTermSums)
  float legs;                    // r + s in single precision, m
  glm::vec3 arrival;             // unit vector from the listener toward Q
  glm::vec3 leaving;             // unit vector from the source toward Q
  const DiffractionEdge* edge;
  glm::vec3 q;                // the point on the edge, m
  glm::vec3 mouth;            // unit direction across the gap the path may pass
  glm::vec3 turn;             // the air wedge turns from face0 toward this (+-normal0)
  float airWedge;             // the air wedge's angle, radians
  float gapWidth = 0.f;       // m; 0: a free edge (engine/gap_probe.h)
  bool slitOwner = false;     // carries its slit's field (once per slit)
  SlitPath slit;              // valid when gapWidth > 0
  glm::vec3 slitCentre{0.f};  // the slit path's point on the slit's centre line, m
  double slitAspect = 0.0;    // slit length / width, as probed (0 to 8)
  double share = 1.0;         // of its UTD field: 1/2 for each edge of a reveal (markReveals)
};

/// Angles (radians, from face 0 in the plane perpendicular to the edge) of the source and the
/// listener seen from Q, the air wedge's angle and its sense (+1: from face 0 toward normal0,
/// -1: the other way); false unless the listener is in the
/// source's wedge and that wedge is wider than about pi (narrower ones cannot shadow: a room's
/// inner corner seen from inside).
bool wedgeAngles(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& source,
                 const glm::vec3& L, bool directVisible, double& phiS, double& phiL, double& wedge,
                 double& sense) {
  auto angleOf = [&](const glm::vec3& p) {  // in [0, 2 pi)
    const glm::vec3 v = p - q;
    double a = std::atan2(double(glm::dot(v, e.normal0)), double(glm::dot(v, e.face0)));
    return a < 0 ? a + 2.0 * kPi : a;
  };
  phiS = angleOf(source);
  phiL = angleOf(L);
  // The source's wedge is the air wedge: [0, open] or, measured from face 0 the other way,
  // [0, 2 pi - open]. The listener must be in it too.
  wedge = double(e.open);
  sense = 1.0;
  if (phiS > wedge) {
    sense = -1.0;
    wedge = 2.0 * kPi - wedge;
    phiS = 2.0 * kPi - phiS;
    phiL = 2.0 * kPi - phiL;
  }
  if (!(phiL > 0.0 && phiL < wedge) || wedge <= 1.05 * kPi) return false;
  // On the shadow boundary itself (|phi - phi'| = pi) the occlusion test that decided
  // direct.visible and the UTD's side of the boundary could disagree by rounding; put the
  // listener 1e-4 rad on the side the direct sound's visibility says.
  constexpr double kBoundary = 1e-4;
  const double dphi = phiL - phiS;
  if (std::abs(std::abs(dphi) - kPi) < kBoundary)
    phiL = phiS + std::copysign(directVisible ? kPi - kBoundary : kPi + kBoundary, dphi);
  return true;
}

/// Zeroes the reflection-boundary terms of the faces whose reflection zone holds the listener.
/// There the face's specular reflection reaches the listener, and it is the tracer's (an image
/// source or a ray path, added in energy), not the coherent sum's; the term that corrects that
/// reflection near its boundary (about -1/2 of it just inside) would stand alone and subtract
/// half a reflection the sum never held. In a doorway through a 0.3 m wall, with the line of
/// sight along its reveals, the six edges' such terms put the direct sound 11 dB above the
/// free field in every band. Outside the zone the term is the diffraction of the face's image
/// source, and kept. Faces: face 0 at angle 0, face n at `wedge`; terms as utdWedgeTerms orders
/// them ([2] singular at face n's boundary, [3] at face 0's).
void dropTracedReflectionTerms(double phiS, double phiL, double wedge,
                               std::array<UtdTerm, 4>& terms) {
  // On the boundary itself (a listener on the axis of a symmetric doorway, seen by both edges
  // of a reveal at their boundaries) it counts as inside, so that both edges decide alike.
  constexpr double kOnBoundary = 1e-6;  // rad, single-precision geometry
  if (phiS < kPi && phiL < kPi - phiS + kOnBoundary) terms[3].cot = 0.0;
  if (phiS > wedge - kPi && phiL > 2.0 * wedge - kPi - phiS - kOnBoundary) terms[2].cot = 0.0;
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
  if (e.open >= float(2.0 * kPi) - 1e-4f) return -e.face0;
  const double lo = std::max({0.0, phiS - kPi, phiL - kPi});
  const double hi = std::min({wedge, phiS + kPi, phiL + kPi});
  const double mid = 0.5 * (lo + hi);
  return float(std::cos(mid)) * e.face0 + float(sense * std::sin(mid)) * e.normal0;
}

/// The path over edge e from source to the listener centre L through the point Q of least
/// length; false when Q lies outside the edge, the wedge cannot diffract toward L, or a leg
/// is blocked (the listener sphere itself is not geometry).
bool edgePath(const DiffractionEdge& e, const glm::vec3& source, const glm::vec3& L,
              bool directVisible, const Tracer& tracer, EdgePath& p) {
  // Stationary point: unfold both points about the edge; Q divides the along-edge
  // separation in the ratio of their distances from the edge line.
  const glm::vec3 ps = source - e.a, pl = L - e.a;
  const float ts = glm::dot(ps, e.direction), tl = glm::dot(pl, e.direction);
  const float rs = glm::length(ps - ts * e.direction), rl = glm::length(pl - tl * e.direction);
  if (!(rs > 1e-4f) || !(rl > 1e-4f)) return false;
  const float t = ts + (tl - ts) * rs / (rs + rl);
  if (!(t > 0.f && t < e.length)) return false;
  const glm::vec3 q = e.a + t * e.direction;
  const glm::vec3 toQ = q - source, toL = L - q;
  const float r = glm::length(toQ), s = glm::length(toL);
  if (!(r > kLegEpsilon && s > kLegEpsilon)) return false;
  double phiS = 0.0, phiL = 0.0, wedge = 0.0, sense = 1.0;
  if (!wedgeAngles(e, q, source, L, directVisible, phiS, phiL, wedge, sense)) return false;
  if (tracer.occluded(TraceRay{source, toQ / r, kLegEpsilon, r - kLegEpsilon})) return false;
  if (tracer.occluded(TraceRay{q, toL / s, kLegEpsilon, s - kLegEpsilon})) return false;
  const double sinB = double(glm::length(glm::cross(toQ / r, e.direction)));
  p.length = double(r) + double(s);
  p.distanceParameter = double(r) * double(s) * sinB * sinB / p.length;
  p.spreading = 1.0 / double(r) * std::sqrt(double(r) / (double(s) * p.length));
  p.prefactor = utdPrefactor(wedge / kPi, sinB);
  p.terms = utdWedgeTerms(wedge / kPi, phiL, phiS);
  dropTracedReflectionTerms(phiS, phiL, wedge, p.terms);
  dropAbsentShadowTerms(phiS, phiL, directVisible, p.terms);
  p.sums = utdTermSums(p.terms);
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

/// Fills p's slit from its gap: the slit's centre line runs along the edge, half the width
/// across the mouth, from `from` to `to` m along it relative to Q (where the gap ends,
/// engine/gap_probe.h); its stationary point, legs and angles as engine/slit.h defines them.
void makeSlit(const glm::vec3& source, const glm::vec3& L, float from, float to, EdgePath& p) {
  const DiffractionEdge& e = *p.edge;
  const glm::vec3 a = e.a + 0.5f * p.gapWidth * p.mouth;
  const glm::vec3 ps = source - a, pl = L - a;
  const float ts = glm::dot(ps, e.direction), tl = glm::dot(pl, e.direction);
  const float rs = glm::length(ps - ts * e.direction), rl = glm::length(pl - tl * e.direction);
  const float z0 = ts + (tl - ts) * rs / std::max(rs + rl, 1e-6f);
  const glm::vec3 c = a + z0 * e.direction, toC = c - source, toL = L - c;
  auto sinFromAxis = [&](const glm::vec3& v) {  // |sin| of v's angle from the slit's axis
    const glm::vec3 across = v - glm::dot(v, e.direction) * e.direction;
    const float l = glm::length(across);
    return l > 0.f ? double(std::abs(glm::dot(across, p.mouth)) / l) : 0.0;
  };
  SlitPath& sp = p.slit;
  sp.r = std::max(double(glm::length(toC)), double(kLegEpsilon));
  sp.s = std::max(double(glm::length(toL)), double(kLegEpsilon));
  sp.sinBeta = double(glm::length(glm::cross(toC, e.direction))) / sp.r;
  const float tq = glm::dot(p.q - e.a, e.direction);
  sp.zFrom = double(tq + from) - double(z0);
  sp.zTo = double(tq + to) - double(z0);
  sp.sinSource = sinFromAxis(toC);
  sp.sinListener = sinFromAxis(toL);
  sp.width = double(p.gapWidth);
  sp.depth = 0.0;
  p.slitCentre = c;
}

/// A slit bounded by two edges (a leaf's rim and its frame's) is found from both; only the
/// first carries its field. Same slit: parallel edges whose centre lines lie within half the
/// wider gap (plus 1 mm) of each other.
void markSlitOwners(std::vector<EdgePath>& paths) {
  for (size_t k = 0; k < paths.size(); ++k) {
    EdgePath& p = paths[k];
    p.slitOwner = p.gapWidth > 0.f;
    for (size_t j = 0; j < k && p.slitOwner; ++j) {
      const EdgePath& o = paths[j];
      if (!o.slitOwner || std::abs(glm::dot(o.edge->direction, p.edge->direction)) < 0.99f)
        continue;
      const glm::vec3 v = p.slitCentre - o.slitCentre;
      const float apart = glm::length(v - glm::dot(v, o.edge->direction) * o.edge->direction);
      if (apart < 0.5f * std::max(o.gapWidth, p.gapWidth) + 1e-3f) p.slitOwner = false;
    }
  }
}

/// Edge e's two faces' in-plane unit vectors pointing away from it: face 0's, and face 1's at
/// angle `open` from it toward normal0 (a free edge's face 1 is face 0's continuation).
std::array<glm::vec3, 2> faceDirections(const DiffractionEdge& e) {
  return {e.face0, std::cos(e.open) * e.face0 + std::sin(e.open) * e.normal0};
}

/// True when edges a and b are the two ends of one flat face: parallel, and the line across
/// from a to b runs along one of a's faces and back along one of b's (a reveal of a thick wall,
/// a slab's two rims).
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

/// The two edges of one face that both diffract the path, the face running along the line of
/// sight between source and L (the near and far edges of a thick wall's doorway seen through it,
/// the face within kAlongSight of that line), bound one side of one opening: each first-order
/// path counts the opening's cut into the direct sound, and both together count it twice
/// (through a 0.3 m wall, the doorway read 9 dB above the Kirchhoff aperture integral at 63 Hz
/// and 5 dB at 125 Hz). Like a slit found from both its edges, that side counts once: each
/// edge takes half. A face seen at a wider angle (a solid wedge's face toward its far rim, 26°
/// from the line in diffraction_test) is not such a pair.
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
      const float apart = glm::distance(a.q, b.q);
      if (!joinedByFace(*a.edge, *b.edge) || !between(a.q) || !between(b.q) || !(apart > 0.f))
        continue;
      if (glm::length(glm::cross((b.q - a.q) / apart, sight)) < kAlongSight)
        paths[j].share = paths[k].share = 0.5;
    }
}

/// Looks for the gap each path may pass (engine/gap_probe.h) and sets its slit; removes the
/// paths whose gap is closed (narrower than kGapNarrowest).
void findSlits(const Tracer& tracer, const glm::vec3& source, const glm::vec3& L,
               std::vector<EdgePath>& paths) {
  std::vector<GapProbe> probes(paths.size());
  for (size_t j = 0; j < paths.size(); ++j) {
    const EdgePath& p = paths[j];
    const DiffractionEdge& e = *p.edge;
    const float t = glm::dot(p.q - e.a, e.direction);
    const float reach = std::min(e.length / float(kSlitMinAspect), kGapFarthest);
    probes[j] = {p.q, p.mouth, reach, e.direction, -t, e.length - t, e.face0, p.turn, p.airWedge};
  }
  std::vector<GapShape> shapes(paths.size());
  probeGaps(tracer, source, L, probes, shapes);
  size_t kept = 0;
  for (size_t j = 0; j < paths.size(); ++j) {
    if (shapes[j].width < 0.f) continue;
    EdgePath& p = paths[kept++] = paths[j];
    p.gapWidth = shapes[j].width;
    if (p.gapWidth > 0.f) {
      makeSlit(source, L, shapes[j].from, shapes[j].to, p);
      p.slitAspect = double(shapes[j].aspect);
    }
  }
  paths.resize(kept);
  markSlitOwners(paths);
}

/// Per path and band, the pressure factors every path carries: the air's attenuation
/// sqrt(exp(-m l)) and the square root of the source's energy weight toward the path.
struct PathGains {
  std::vector<double> utd;   // times the UTD path's spreading
  std::vector<double> slit;  // for the slit path
  /// Per path, its UTD coefficient at band b's anchor frequencies (utdAnchors).
  std::vector<std::array<C, kUtdAnchorsPerBand>> anchors;
};

/// Every path's UTD coefficient at band b's anchor frequencies, into gains.anchors.
void utdAnchors(int b, const std::vector<EdgePath>& paths, float speedOfSound,
                PathGains& gains) {
  gains.anchors.resize(paths.size());
  for (int a = 0; a < kUtdAnchorsPerBand; ++a) {
    const double k = 2.0 * kPi * diffractionFrequencyHz(b, utdAnchorIndex(a)) / speedOfSound;
    for (size_t j = 0; j < paths.size(); ++j) {
      const EdgePath& q = paths[j];
      gains.anchors[j][size_t(a)] =
          utdScaled(q.terms, q.sums, q.prefactor, k * q.distanceParameter);
    }
  }
}

/// The slit whose gap the line of sight from source to L passes through, if any: an owner
/// path's gap (from its edge across `mouth` for gapWidth, along the edge where the gap runs:
/// the slit's extent) that the segment crosses. That slit's field is then the direct sound's own at the frequencies where
/// the slit model holds (engine/slit.h: it is driven by the incident pressure at its mouth).
const EdgePath* slitOnLineOfSight(const std::vector<EdgePath>& paths, const glm::vec3& source,
                                  const glm::vec3& L) {
  constexpr float kTolerance = 1e-4f;  // m, single-precision geometry
  const glm::vec3 d = L - source;
  for (const EdgePath& p : paths) {
    if (!(p.gapWidth > 0.f) || !p.slitOwner) continue;
    const DiffractionEdge& e = *p.edge;
    const glm::vec3 normal = glm::cross(e.direction, p.mouth);  // the slit's plane
    const float den = glm::dot(d, normal);
    if (!(std::abs(den) > 1e-9f)) continue;
    const float t = glm::dot(e.a - source, normal) / den;
    if (!(t > 0.f && t < 1.f)) continue;
    const glm::vec3 v = source + t * d - e.a;
    const float across = glm::dot(v, p.mouth), along = glm::dot(v, e.direction);
    const float z0 = glm::dot(p.slitCentre - e.a, e.direction);  // the slit's own point
    if (across >= -kTolerance && across <= p.gapWidth + kTolerance &&
        along >= z0 + float(p.slit.zFrom) - kTolerance &&
        along <= z0 + float(p.slit.zTo) + kTolerance)
      return &p;
  }
  return nullptr;
}

/// Scratch of slitLoading: the coupled slits, the path each belongs to, their factors, and
/// per path its factor.
struct SlitLoading {
  std::vector<CoupledSlit> slits;
  std::vector<size_t> path;
  std::vector<C> factors, perPath;
};

/// Per path, the factor its slit's field takes from the slits' mutual loading at wavenumber k
/// (engine/slit.h, mutualLoading), into out.perPath: owner paths whose slit model holds (weight
/// s > 0) are coupled; 1 for the rest.
void slitLoading(const std::vector<EdgePath>& paths, const PathGains& gains, double k,
                 SlitLoading& out) {
  out.slits.clear();
  out.path.clear();
  out.perPath.assign(paths.size(), C(1.0, 0.0));
  for (size_t j = 0; j < paths.size(); ++j) {
    const EdgePath& q = paths[j];
    if (!(q.gapWidth > 0.f) || !q.slitOwner) continue;
    const double kt = k * q.slit.sinBeta, x = kt * q.slit.width;
    if (!(slitWeight(x, q.slitAspect) > 0.0)) continue;
    const glm::dvec3 along(q.edge->direction);
    out.slits.push_back({glm::dvec3(q.slitCentre), along,
                         glm::normalize(glm::cross(along, glm::dvec3(q.mouth))), x, kt,
                         gains.slit[j] * std::polar(1.0 / q.slit.r, -k * q.slit.r)});
    out.path.push_back(j);
  }
  if (out.slits.size() < 2) return;
  out.factors.resize(out.slits.size());
  mutualLoading(out.slits, out.factors);
  for (size_t i = 0; i < out.path.size(); ++i) out.perPath[out.path[i]] = out.factors[i];
}

/// The direct sound in the coherent sum: its amplitude (0 when not visible) and distance (m),
/// and the slit its line of sight passes through (null: none).
struct DirectPart {
  double amplitude;
  float distance;
  const EdgePath* slit;
};

/// |p|^2 of the direct sound plus every path, averaged over band b's frequencies. A path
/// through a gap adds its slit's field (engine/slit.h) with weight s = slitWeight(k_t w,
/// aspect) and its edge's UTD field with weight 1 - s; a direct sound whose line of sight
/// passes that slit keeps the weight 1 - s too (the slit's field carries the rest).
double bandMeanSquare(int b, const std::vector<EdgePath>& paths, const PathGains& gains,
                      const DirectPart& direct, float speedOfSound) {
  double acc = 0.0;
  SlitLoading loading;
  for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
    const double k = 2.0 * kPi * diffractionFrequencyHz(b, i) / speedOfSound;
    slitLoading(paths, gains, k, loading);
    double directAmplitude = direct.amplitude;
    if (const EdgePath* q = direct.slit)
      directAmplitude *= 1.0 - slitWeight(k * q->slit.sinBeta * q->slit.width, q->slitAspect);
    C p = directAmplitude * pathPhasor(k * double(direct.distance));
    C diffracted(0.0, 0.0);
    for (size_t j = 0; j < paths.size(); ++j) {
      const EdgePath& q = paths[j];
      double amplitude = gains.utd[j];
      if (q.gapWidth > 0.f) {
        const double s = slitWeight(k * q.slit.sinBeta * q.slit.width, q.slitAspect);
        if (s > 0.0 && q.slitOwner)
          p += s * gains.slit[j] * loading.perPath[j] * slitPressure(q.slit, k);
        if (s >= 1.0) continue;
        amplitude *= 1.0 - s;
      }
      const C d = interpolatedUtd(gains.anchors[j], i);
      const C e = pathPhasor(k * q.length);  // e^{-jkl} = c - j s
      const double c = e.real(), sn = -e.imag();
      // amplitude * d * e^{-jkl}, written out (std::complex's operator* checks for NaN)
      diffracted += amplitude * C(d.real() * c + d.imag() * sn, d.imag() * c - d.real() * sn);
    }
    p += diffracted / std::sqrt(k);
    acc += std::norm(p);
  }
  return acc / kDiffractionFrequenciesPerBand;
}

/// Per path, the source's energy weight toward its edge point Q (scene/directivity.h); empty
/// for an omni source.
std::vector<Bands> leavingWeights(const std::vector<EdgePath>& paths, const Directivity& d,
                                  const glm::vec3& forward) {
  std::vector<Bands> w;
  if (d.omni()) return w;
  for (const EdgePath& p : paths) w.push_back(directivityWeight(d, glm::dot(forward, p.leaving)));
  return w;
}

/// Band intensity (1/m^2, the scale of 1/(4 pi r^2)) of the coherent sum of the direct sound
/// (when visible; its directivity weight is already in direct.intensity) and the edge paths,
/// each path's pressure scaled by the square root of its energy weight (none when empty);
/// throughSlit: the slit the line of sight passes (slitOnLineOfSight), or null.
Bands coherentIntensity(const std::vector<EdgePath>& paths, const DirectSound& direct,
                        const EdgePath* throughSlit, float speedOfSound, const Bands& airPerMetre,
                        const std::vector<Bands>& weights) {
  Bands intensity(0.f);
  PathGains gains{std::vector<double>(paths.size()), std::vector<double>(paths.size()), {}};
  for (int b = 0; b < kNumBands; ++b) {
    for (size_t j = 0; j < paths.size(); ++j) {
      const double w = weights.empty() ? 1.0 : std::sqrt(double(weights[j][b]));
      gains.utd[j] = paths[j].share * paths[j].spreading *
                     std::exp(-0.5 * double(airPerMetre[b]) * paths[j].length);
      if (!weights.empty()) gains.utd[j] *= w;
      gains.slit[j] =
          w * std::exp(-0.5 * double(airPerMetre[b]) * (paths[j].slit.r + paths[j].slit.s));
    }
    const double directAmplitude =
        direct.visible ? std::sqrt(4.0 * kPi * double(direct.intensity[b])) : 0.0;
    utdAnchors(b, paths, speedOfSound, gains);
    const double meanSquare = bandMeanSquare(
        b, paths, gains, {directAmplitude, direct.distance, throughSlit}, speedOfSound);
    intensity[b] = float(meanSquare / (4.0 * kPi));
  }
  return intensity;
}

/// The direct sound's band intensity with nothing in its way (1/m^2): spreading over the
/// direct distance, the air's attenuation and the source's weight toward the listener.
Bands unobstructedIntensity(const glm::vec3& source, const glm::vec3& L, const DirectSound& d,
                            const Bands& airPerMetre, const Directivity& directivity,
                            const glm::vec3& forward) {
  Bands i = exp(airPerMetre * -d.distance) * (1.f / (4.f * float(kPi) * d.distance * d.distance));
  const glm::vec3 v = L - source;
  const float length = glm::length(v);
  if (!directivity.omni() && length > 0.f)
    i *= directivityWeight(directivity, glm::dot(forward, v / length));
  return i;
}

}  // namespace

double diffractionFrequencyHz(int band, int i) {
  return bandCentreExactHz(band) * std::exp2((i + 0.5) / kDiffractionFrequenciesPerBand - 0.5);
}

EdgeDiffraction::EdgeDiffraction(const Mesh& mesh) : edges_(candidateEdges(mesh)) {}

size_t EdgeDiffraction::apply(const Tracer& tracer, const glm::vec3& source,
                              const ListenerSphere& listener, float speedOfSound,
                              const Bands& airPerMetre, DirectSound& direct,
                              const Directivity& directivity, const glm::vec3& forward,
                              std::vector<uint32_t>* usedEdges) const {
  // Diffraction needs the free line of sight: a direct path through transmitting surfaces is
  // in the shadow for the edges, and its energy adds to theirs incoherently (the edge paths'
  // legs are unoccluded, the transmitted path crosses a surface: no path is counted twice).
  const bool lineOfSight = direct.lineOfSight();
  std::vector<EdgePath> paths;
  float shortest = direct.visible ? direct.distance : 1e30f;
  glm::vec3 shortestDir = direct.direction;
  for (const DiffractionEdge& e : edges_) {
    EdgePath p;
    if (!edgePath(e, source, listener.position, lineOfSight, tracer, p)) continue;
    paths.push_back(p);
    if (p.legs < shortest) {
      shortest = p.legs;
      shortestDir = p.arrival;
    }
  }
  findSlits(tracer, source, listener.position, paths);
  markReveals(source, listener.position, paths);
  if (usedEdges) {
    usedEdges->clear();
    for (const EdgePath& p : paths) usedEdges->push_back(uint32_t(p.edge - edges_.data()));
  }
  if (paths.empty()) return 0;
  for (const EdgePath& p : paths)
    if (p.gapWidth > 0.f && float(p.slit.r + p.slit.s) < shortest) {
      shortest = float(p.slit.r + p.slit.s);
      shortestDir = glm::normalize(p.slitCentre - listener.position);
    }
  DirectSound coherent = direct;
  coherent.visible = lineOfSight;
  const Bands through = lineOfSight || !direct.visible ? Bands(0.f) : direct.intensity;
  const EdgePath* throughSlit =
      lineOfSight ? slitOnLineOfSight(paths, source, listener.position) : nullptr;
  direct.intensity = coherentIntensity(paths, coherent, throughSlit, speedOfSound, airPerMetre,
                                       leavingWeights(paths, directivity, forward)) +
                     through;
  // An obstruction adds no energy to the path it blocks: with the line of sight blocked, never
  // more than the direct sound with nothing in its way. (With it free, the edges' field may
  // lift the sum above it: the lit side's Fresnel ripple, exact by Biot-Tolstoy-Medwin.)
  if (!lineOfSight) {
    const Bands free =
        unobstructedIntensity(source, listener.position, direct, airPerMetre, directivity, forward);
    for (int b = 0; b < kNumBands; ++b)
      direct.intensity[b] = std::min(direct.intensity[b], free[b]);
  }
  direct.visible = true;
  direct.distance = shortest;
  direct.delaySeconds = shortest / speedOfSound;
  direct.direction = shortestDir;
  return paths.size();
}

}  // namespace dpc
