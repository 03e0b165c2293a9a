#include "engine/small_reflectors.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <glm/geometric.hpp>
#include <numbers>
#include <span>

#include "engine/diffraction.h"
#include "engine/diffraction_edges.h"

namespace dpc {

namespace {

constexpr uint8_t kFront = 1, kBack = 2;
/// A probe starts an eighth of the band's centre wavelength off the plane on the lit side and
/// runs twice as far across it: a parallel surface that near (a panel on a wall, the wall behind
/// it) reflects with the plane, its phase shifted by the path it saves or adds (up to pi / 2).
constexpr double kProbeWavelengths = 0.125;
/// A probe's hit counts as coplanar when its normal is within about 2.6 degrees of the face's.
constexpr double kCoplanarCos = 0.999;
/// The surface's own part is integrated over its triangles when it has at most kOwnTriangles
/// (otherwise the probes find it). Over a piece its phase is taken linear between the corners'
/// and integrated exactly, the taper at its centroid; a triangle is halved across its longest
/// side while its corners' phases spread over more than kPhaseSpread rad, the phase's curvature
/// departs from linear by more than kPhaseCurvature rad or the taper changes by more than
/// kTaperSpread across it, when the surface has at most kFineTriangles triangles (else whole):
/// at least kOwnDepth times, and as often as a triangle's longest side needs to reach the size
/// the curvature test accepts (two halvings per halving of the length), at most kMaxOwnDepth.
/// Pieces past the taper's end are dropped whole, so a triangle far larger than the zones (a
/// ground kilometres wide) costs what the part within the taper does.
constexpr size_t kOwnTriangles = 16384, kFineTriangles = 1024;
constexpr double kPhaseSpread = 3.0, kPhaseCurvature = 0.3, kTaperSpread = 0.25;
constexpr int kOwnDepth = 16, kMaxOwnDepth = 96;
/// Terms of the series for a piece's mean phase factor: at a spread of kPhaseSpread the last is
/// below 1e-16.
constexpr int kSeriesTerms = 28;

glm::dvec3 triangleNormal(const Mesh& mesh, size_t t) {
  const auto& v = mesh.triangles[t];
  const glm::dvec3 a(mesh.vertices[v[0]]), b(mesh.vertices[v[1]]), c(mesh.vertices[v[2]]);
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double length = glm::length(n);
  return length > 0.0 ? n / length : glm::dvec3(0.0);
}

/// Per flat surface, a unit normal of one of its triangles: the sides are front and back of it.
std::vector<glm::dvec3> referenceNormals(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                                         size_t count) {
  std::vector<glm::dvec3> out(count, glm::dvec3(0.0));
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    if (out[surfaces[t]] == glm::dvec3(0.0)) out[surfaces[t]] = triangleNormal(mesh, t);
  return out;
}

/// Per flat surface, the length of its edges convex from its reference front (0) and back (1):
/// the air wedge on that side wider than pi (by kFlatEdge), or a free rim (air all round).
/// The wedge `open` of an edge lies on face 0's normal0 side, and on the side of face 1 that
/// turns back toward face 0.
std::vector<std::array<double, 2>> convexLengths(const std::vector<DiffractionEdge>& edges,
                                                 const std::vector<glm::dvec3>& reference) {
  constexpr double kPi = std::numbers::pi;
  std::vector<std::array<double, 2>> out(reference.size(), {0.0, 0.0});
  for (const DiffractionEdge& e : edges) {
    const double open = double(e.open), length = double(e.length);
    if (isFreeEdge(e)) {
      out[e.surfaces[0]][0] += length;
      out[e.surfaces[0]][1] += length;
      continue;
    }
    const glm::dvec3 f0(e.face0), n0(e.normal0);
    const std::array<glm::dvec3, 2> toward{n0, std::sin(open) * f0 - std::cos(open) * n0};
    for (size_t f = 0; f < 2; ++f) {
      const uint32_t s = e.surfaces[f];
      const bool openInFront = glm::dot(toward[f], reference[s]) > 0.0;
      const double front = openInFront ? open : 2.0 * kPi - open;
      if (front > kPi + kFlatEdge) out[s][0] += length;
      if (2.0 * kPi - front > kPi + kFlatEdge) out[s][1] += length;
    }
  }
  return out;
}

/// Per triangle of one mesh, its kFront / kBack bits; `surfaces` and `edges` the mesh's
/// flatSurfaces and candidateEdges.
std::vector<uint8_t> freeSides(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                               const std::vector<DiffractionEdge>& edges) {
  const std::vector<double> boundary = surfaceBoundaries(mesh, surfaces);
  const std::vector<glm::dvec3> reference = referenceNormals(mesh, surfaces, boundary.size());
  const std::vector<std::array<double, 2>> convex = convexLengths(edges, reference);
  std::vector<uint8_t> out(mesh.triangles.size(), 0);
  for (size_t t = 0; t < out.size(); ++t) {
    const uint32_t s = surfaces[t];
    if (!(boundary[s] > 0.0)) continue;
    const bool same = glm::dot(triangleNormal(mesh, t), reference[s]) >= 0.0;
    for (size_t side = 0; side < 2; ++side)
      if (convex[s][side] >= kFreeStanding * boundary[s])
        out[t] |= (side == 0) == same ? kFront : kBack;
  }
  return out;
}

/// s: the zone number squared, rho^2 = (x_u / ru)^2 + (x_v / rv)^2 in the zone's axes; the
/// Fresnel phase there is pi s (pi at the first zone's rim).
glm::dvec2 zonePoint(const SmallReflectors::Zone& z, double ru, double rv, const glm::dvec3& x) {
  const glm::dvec3 d = x - z.point;
  return {glm::dot(d, z.u) / ru, glm::dot(d, z.v) / rv};
}

/// Least |p|^2 over the 2-D triangle (a, b, c): 0 when it holds the origin.
double leastSquaredRadius(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  auto cross = [](const glm::dvec2& p, const glm::dvec2& q) { return p.x * q.y - p.y * q.x; };
  const double d0 = cross(b - a, -a), d1 = cross(c - b, -b), d2 = cross(a - c, -c);
  if ((d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0)) return 0.0;
  auto toSegment = [](const glm::dvec2& p, const glm::dvec2& q) {
    const glm::dvec2 e = q - p;
    const double len2 = glm::dot(e, e);
    const double t = len2 > 0.0 ? std::clamp(-glm::dot(p, e) / len2, 0.0, 1.0) : 0.0;
    const glm::dvec2 x = p + t * e;
    return glm::dot(x, x);
  };
  return std::min({toSegment(a, b), toSegment(b, c), toSegment(c, a)});
}

/// The band's frequencies over its centre's, 2^((i + 1/2) / 4 - 1/2): kBandPoints log-spaced
/// across the octave. At frequency m fc the zone number squared is m times its value at fc.
constexpr std::array<double, SmallReflectors::kBandPoints> bandMultipliers() {
  return {0.7711054127039704, 0.9170040432046712, 1.0905077326652577, 1.2968395546510096};
}
using BandSums = std::array<std::complex<double>, SmallReflectors::kBandPoints>;

/// Adds weight taper(s m) e^{j (phase - pi s) m} at each of the band's frequencies m, s the zone
/// number squared and `phase` (rad) a shift, both at the centre frequency.
void addAt(BandSums& sums, double weight, double s, double phase) {
  const auto m = bandMultipliers();
  for (size_t i = 0; i < sums.size(); ++i)
    sums[i] += std::polar(weight * SmallReflectors::taper(s * m[i]),
                          (phase - std::numbers::pi * s) * m[i]);
}

/// The mean of e^{j phi} over a triangle whose phase phi is linear between its corners' p1, p2,
/// p3 (rad): 2 e[j p1, j p2, j p3], the divided difference of exp over the simplex
/// (Hermite-Genocchi), summed as its series about the mean phase (stable at any spread).
std::complex<double> meanPhaseFactor(double p1, double p2, double p3) {
  using C = std::complex<double>;
  const double c = (p1 + p2 + p3) / 3.0;
  const C w1(0.0, p1 - c), w2(0.0, p2 - c), w3(0.0, p3 - c);
  C h1(1.0), h2(1.0), h3(1.0), sum(0.5);  // complete homogeneous sums of degree 0, over 2!
  double factorial = 2.0;
  for (int n = 1; n <= kSeriesTerms; ++n) {
    h1 *= w1;           // of w1
    h2 = h1 + w2 * h2;  // of w1, w2
    h3 = h2 + w3 * h3;  // of w1, w2, w3
    factorial *= double(n + 2);
    sum += h3 / factorial;
  }
  return 2.0 * std::polar(1.0, c) * sum;
}

/// Adds the integral of taper(s) e^{j (shift d - pi s)} dA (m^2) over triangle (a, b, c) (m) at
/// each of the band's frequencies (s the zone number squared, d the height before the plane,
/// `shift` rad per metre at the centre frequency), halved across its longest side (in the
/// zone's axes) while kPhaseSpread, kPhaseCurvature or kTaperSpread is exceeded at the highest.
void addOwn(BandSums& sums, const SmallReflectors::Zone& z, double ru, double rv, double shift,
            const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, int depth) {
  const auto m = bandMultipliers();
  const glm::dvec2 pa = zonePoint(z, ru, rv, a), pb = zonePoint(z, ru, rv, b),
                   pc = zonePoint(z, ru, rv, c);
  const double least = leastSquaredRadius(pa, pb, pc);
  if (least * m.front() >= SmallReflectors::kTaperEnd) return;
  const double ab = glm::dot(pb - pa, pb - pa), bc = glm::dot(pc - pb, pc - pb),
               ca = glm::dot(pa - pc, pa - pc);
  const double pi = std::numbers::pi;
  const std::array<double, 3> phase{
      shift * glm::dot(a - z.point, z.normal) - pi * glm::dot(pa, pa),
      shift * glm::dot(b - z.point, z.normal) - pi * glm::dot(pb, pb),
      shift * glm::dot(c - z.point, z.normal) - pi * glm::dot(pc, pc)};
  const double spread =
      *std::max_element(phase.begin(), phase.end()) - *std::min_element(phase.begin(), phase.end());
  const double curvature = 0.25 * pi * std::max({ab, bc, ca});
  const double most = std::max({glm::dot(pa, pa), glm::dot(pb, pb), glm::dot(pc, pc)});
  const double taperSpread =
      SmallReflectors::taper(least * m.back()) - SmallReflectors::taper(most * m.back());
  if (depth == 0 || (spread * m.back() <= kPhaseSpread && curvature * m.back() <= kPhaseCurvature &&
                     taperSpread <= kTaperSpread)) {
    const glm::dvec2 centroid = (pa + pb + pc) / 3.0;
    const double area = 0.5 * glm::length(glm::cross(b - a, c - a)),
                 s = glm::dot(centroid, centroid);
    for (size_t i = 0; i < sums.size(); ++i)
      sums[i] += area * SmallReflectors::taper(s * m[i]) *
                 meanPhaseFactor(phase[0] * m[i], phase[1] * m[i], phase[2] * m[i]);
    return;
  }
  if (ab >= bc && ab >= ca) {
    addOwn(sums, z, ru, rv, shift, a, 0.5 * (a + b), c, depth - 1);
    addOwn(sums, z, ru, rv, shift, 0.5 * (a + b), b, c, depth - 1);
  } else if (bc >= ca) {
    addOwn(sums, z, ru, rv, shift, a, b, 0.5 * (b + c), depth - 1);
    addOwn(sums, z, ru, rv, shift, a, 0.5 * (b + c), c, depth - 1);
  } else {
    addOwn(sums, z, ru, rv, shift, a, b, 0.5 * (c + a), depth - 1);
    addOwn(sums, z, ru, rv, shift, 0.5 * (c + a), b, c, depth - 1);
  }
}

/// How often addOwn may halve triangle (a, b, c): kOwnDepth, or as often as its longest side
/// (in zone units) needs to pass the curvature test at the band's highest frequency.
int halvingsFor(const SmallReflectors::Zone& z, double ru, double rv, const glm::dvec3& a,
                const glm::dvec3& b, const glm::dvec3& c) {
  const glm::dvec2 pa = zonePoint(z, ru, rv, a), pb = zonePoint(z, ru, rv, b),
                   pc = zonePoint(z, ru, rv, c);
  const double side = std::sqrt(std::max(
      {glm::dot(pb - pa, pb - pa), glm::dot(pc - pb, pc - pb), glm::dot(pa - pc, pa - pc)}));
  const double accepted =
      std::sqrt(kPhaseCurvature / (0.25 * std::numbers::pi * bandMultipliers().back()));
  if (!(side > accepted)) return kOwnDepth;
  const double needed = 2.0 * std::ceil(std::log2(side / accepted)) + 2.0;
  return int(std::clamp(needed, double(kOwnDepth), double(kMaxOwnDepth)));
}

/// Adds the surface's own triangles `own` that face as `facing` does (the reflecting
/// triangle's normal: a double-sided copy and a curved surface's far side are left out).
void addOwnSurface(BandSums& sums, const std::vector<WorldTriangle>& world,
                   std::span<const uint32_t> own, const glm::dvec3& facing,
                   const SmallReflectors::Zone& z, double ru, double rv, double shift) {
  const bool fine = own.size() <= kFineTriangles;
  for (uint32_t t : own) {
    if (t >= world.size()) continue;
    const glm::dvec3 a(world[t].v0), b(world[t].v1), c(world[t].v2);
    if (glm::dot(glm::cross(b - a, c - a), facing) < 0.0) continue;
    addOwn(sums, z, ru, rv, shift, a, b, c, fine ? halvingsFor(z, ru, rv, a, b, c) : 0);
  }
}

/// Adds one mesh's flat surfaces (`surfaces`, flatSurfaces of it) to `members`, its triangles
/// numbered from `first`.
void addSurfaces(const std::vector<uint32_t>& surfaces, uint32_t first,
                 std::vector<uint32_t>& surfaceOf, std::vector<std::vector<uint32_t>>& members) {
  const auto offset = uint32_t(members.size());
  for (size_t t = 0; t < surfaces.size(); ++t) {
    const uint32_t s = offset + surfaces[t];
    surfaceOf.push_back(s);
    if (s >= members.size()) members.resize(s + 1);
    members[s].push_back(first + uint32_t(t));
  }
}

}  // namespace

SmallReflectors::SmallReflectors(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                                 const std::vector<DiffractionEdge>& edges,
                                 const std::vector<ObjectDesc>& objects)
    : free_(freeSides(mesh, surfaces, edges)) {
  addSurfaces(surfaces, 0, surface_, members_);
  for (const ObjectDesc& o : objects) {
    const std::vector<uint32_t> objectSurfaces = flatSurfaces(o.mesh);
    const std::vector<uint8_t> sides =
        freeSides(o.mesh, objectSurfaces, candidateEdges(o.mesh, objectSurfaces));
    addSurfaces(objectSurfaces, uint32_t(free_.size()), surface_, members_);
    free_.insert(free_.end(), sides.begin(), sides.end());
  }
  // Sunflower: sample k at radius sqrt((k + 1/2) / K), turned by the golden angle each step.
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (size_t k = 0; k < samples_.size(); ++k) {
    const double r = std::sqrt((double(k) + 0.5) / double(samples_.size()));
    samples_[k] = r * glm::dvec2(std::cos(golden * double(k)), std::sin(golden * double(k)));
  }
}

bool SmallReflectors::standsFree(uint32_t t, bool front) const {
  return t < free_.size() && (free_[t] & (front ? kFront : kBack)) != 0;
}

SmallReflectors::Zone SmallReflectors::zoneOf(const glm::dvec3& point, const glm::dvec3& litNormal,
                                              const glm::dvec3& incoming, double before,
                                              double after) {
  const double along = glm::dot(incoming, litNormal);
  glm::dvec3 u = incoming - along * litNormal;  // in the plane, in the plane of incidence
  if (glm::length(u) < 1e-9)                    // normal incidence: any direction in the plane
    u = glm::cross(litNormal,
                   std::abs(litNormal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0));
  u = glm::normalize(u);
  return Zone{point,
              litNormal,
              u,
              glm::cross(litNormal, u),
              std::max(kGrazingCos, std::abs(along)),
              before * after / (before + after)};
}

double SmallReflectors::taper(double s) {
  if (s <= kTaperStart) return 1.0;
  if (s >= kTaperEnd) return 0.0;
  const double c = std::cos(0.5 * std::numbers::pi * (s - kTaperStart) / (kTaperEnd - kTaperStart));
  return c * c;
}

SmallReflectors::Ratio SmallReflectors::energyRatio(const Tracer& tracer,
                                                    const std::vector<WorldTriangle>& world,
                                                    uint32_t t, const Zone& z, double radius,
                                                    double wavelength, double lasting) const {
  const uint32_t surface = surface_[t];
  const auto m = bandMultipliers();
  const double ru = radius / z.cosIncidence, rv = radius;
  const double reach = kTaperEnd / m.front();  // s at fc where the lowest frequency's taper ends
  const std::span<const uint32_t> own = members_[surface];
  const bool exact = own.size() <= kOwnTriangles;
  const double k = 2.0 * std::numbers::pi / wavelength;  // a surface d before the plane
  const double shift = 2.0 * k * z.cosIncidence;         // shortens the path by 2 d cos(theta)
  BandSums sums{}, lastingSums{};                        // m^2: all surface, what lasts
  if (exact)
    addOwnSurface(
        sums, world, own,
        glm::cross(glm::dvec3(world[t].v1 - world[t].v0), glm::dvec3(world[t].v2 - world[t].v0)), z,
        ru, rv, shift);
  if (exact) lastingSums = sums;
  // The samples spread evenly over the ellipse s <= reach, of area reach pi ru rv.
  const double cell = reach * std::numbers::pi * ru * rv / double(samples_.size());
  const double depth = kProbeWavelengths * wavelength;
  for (const glm::dvec2& p : samples_) {
    const glm::dvec2 q = std::sqrt(reach) * p;
    const glm::dvec3 x = z.point + ru * q.x * z.u + rv * q.y * z.v + depth * z.normal;
    SurfaceHit hit;
    if (!tracer.intersect(TraceRay{glm::vec3(x), glm::vec3(-z.normal), 0.f, float(2.0 * depth)},
                          hit))
      continue;
    // Its own surface counts at any tilt (a fold of up to kFlatEdge), integrated already when
    // exact; other surface only parallel to the plane.
    const bool onOwn = hit.triangle < surface_.size() && surface_[hit.triangle] == surface;
    if (exact && onOwn) continue;
    if (!onOwn && std::abs(glm::dot(glm::dvec3(hit.normal), z.normal)) < kCoplanarCos) continue;
    const double before = depth - double(hit.t);  // m the surface lies before the plane
    addAt(sums, cell, glm::dot(q, q), shift * before);
    if (onOwn || std::abs(before) <= lasting)
      addAt(lastingSums, cell, glm::dot(q, q), shift * before);
  }
  // |p / p_image| = (pi / Z) |sum| at each frequency, Z = pi ru rv / m its first zone's area.
  const auto energy = [&](const BandSums& s) {
    double e = 0.0;
    for (size_t i = 0; i < s.size(); ++i) {
      const double ratio = std::abs(s[i]) * m[i] / (ru * rv);
      e += ratio * ratio;
    }
    return e / double(s.size());
  };
  return {energy(sums), energy(lastingSums)};
}

Bands SmallReflectors::share(const Tracer& tracer, const std::vector<WorldTriangle>& world,
                             uint32_t t, const Zone& zone, double speedOfSound) const {
  Bands out(1.f);
  if (t >= surface_.size() || !(zone.distance > 0.0) || !(speedOfSound > 0.0)) return out;
  // Surface this near the plane stays within an eighth of every band's wavelength.
  const double lasting = kProbeWavelengths * speedOfSound / bandCentreExactHz(kNumBands - 1);
  for (int b = 0; b < kNumBands; ++b) {
    const double wavelength = speedOfSound / bandCentreExactHz(b);
    const double radius = std::sqrt(wavelength * zone.distance);
    const Ratio r = energyRatio(tracer, world, t, zone, radius, wavelength, lasting);
    // From the first band the surface and what is coplanar with it reflect whole, the higher
    // bands' smaller zones lie further inside them; the integral's swing about 1 there is left
    // out, as it is above 1. A band made whole by a parallel surface farther behind (within an
    // eighth of its wavelength only) is not: the higher bands' probes do not reach it.
    if (r.lasting >= 1.0) break;
    out[b] = float(std::min(1.0, r.total));
  }
  return out;
}

Bands SmallReflectors::firstOrderShare(const Tracer& tracer,
                                       const std::vector<WorldTriangle>& world, uint32_t t,
                                       const glm::vec3& point, const glm::vec3& source,
                                       double length, double speedOfSound) const {
  const glm::dvec3 p(point);
  const glm::dvec3 in = p - glm::dvec3(source);
  const double before = glm::length(in);
  if (t >= world.size() || !(before > 0.0) || !(length - before > 0.0)) return Bands(1.f);
  const WorldTriangle& w = world[t];
  const glm::dvec3 n = glm::normalize(glm::cross(glm::dvec3(w.v1 - w.v0), glm::dvec3(w.v2 - w.v0)));
  const bool front = glm::dot(n, in) < 0.0;  // the sound arrives on the normal's side
  if (!standsFree(t, front)) return Bands(1.f);
  return share(tracer, world, t, zoneOf(p, front ? n : -n, in / before, before, length - before),
               speedOfSound);
}

}  // namespace dpc
