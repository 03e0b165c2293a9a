#include "engine/diffraction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <numbers>
#include <unordered_map>

#include "engine/gap_probe.h"
#include "engine/slit.h"
#include "scene/mesh_topology.h"

namespace dpc {

namespace {

using C = std::complex<double>;
constexpr double kPi = std::numbers::pi;

glm::vec3 safeNormalize(const glm::vec3& v) {
  const float l = glm::length(v);
  return l > 0.f ? v / l : glm::vec3(0.f);
}

/// Undirected edge (welded vertex ids, smaller first, as one key) -> the triangles using it
/// (first two) and the count.
struct EdgeUse {
  uint32_t tri[2]{};
  int count = 0;
};

std::unordered_map<uint64_t, EdgeUse> edgeUses(const Mesh& mesh, const std::vector<uint32_t>& id) {
  std::unordered_map<uint64_t, EdgeUse> uses;
  uses.reserve(mesh.triangles.size() * 3);
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) {
      const uint64_t u = id[mesh.triangles[t][size_t(i)]],
                     v = id[mesh.triangles[t][size_t((i + 1) % 3)]];
      EdgeUse& e = uses[u < v ? (u << 32 | v) : (v << 32 | u)];
      if (e.count < 2) e.tri[e.count] = t;
      ++e.count;
    }
  return uses;
}

glm::vec3 normalOf(const Mesh& mesh, uint32_t t) {
  const auto& tr = mesh.triangles[t];
  return safeNormalize(glm::cross(mesh.vertices[tr[1]] - mesh.vertices[tr[0]],
                                  mesh.vertices[tr[2]] - mesh.vertices[tr[0]]));
}

/// In-plane unit vector of triangle t from the edge (ia, ib) toward its third vertex.
glm::vec3 inward(const Mesh& mesh, const std::vector<uint32_t>& id, uint32_t t, uint32_t ia,
                 uint32_t ib, const glm::vec3& dir) {
  const auto& tr = mesh.triangles[t];
  uint32_t third = tr[0];
  for (uint32_t v : tr)
    if (id[v] != ia && id[v] != ib) third = v;
  glm::vec3 w = mesh.vertices[third] - mesh.vertices[ia];
  w -= glm::dot(w, dir) * dir;
  return safeNormalize(w);
}

/// The candidate edge of welded edge `key`; false when it has no wedge (non-manifold,
/// degenerate or flat).
bool makeEdge(const Mesh& mesh, const std::vector<uint32_t>& id, uint64_t key, const EdgeUse& use,
              DiffractionEdge& e) {
  if (use.count > 2) return false;  // non-manifold: no wedge defined
  const uint32_t ia = uint32_t(key >> 32), ib = uint32_t(key & 0xffffffffu);
  e.a = mesh.vertices[ia];
  e.b = mesh.vertices[ib];
  e.length = glm::length(e.b - e.a);
  if (!(e.length > 0.f)) return false;
  e.direction = (e.b - e.a) / e.length;
  e.face0 = inward(mesh, id, use.tri[0], ia, ib, e.direction);
  e.normal0 = normalOf(mesh, use.tri[0]);
  if (glm::length(e.face0) == 0.f || glm::length(e.normal0) == 0.f) return false;
  if (use.count == 1) {
    e.open = float(2.0 * kPi);  // half-plane: one wedge of 2 pi
    return true;
  }
  // Angle of face 1 from face 0, turning toward normal0. Which of the two wedges
  // (open, 2 pi - open) holds air is decided per frame by where the source is, so the
  // mesh's winding does not matter.
  const glm::vec3 f1 = inward(mesh, id, use.tri[1], ia, ib, e.direction);
  double ang = std::atan2(double(glm::dot(f1, e.normal0)), double(glm::dot(f1, e.face0)));
  if (ang < 0) ang += 2.0 * kPi;
  e.open = float(ang);
  return !(std::abs(ang - kPi) < 0.05 * kPi);  // flat: no wedge
}

/// An edge lying in another triangle (a partition's rim along the floor, a box standing on
/// it) is sealed by that surface: no wedge of air around it. A triangle can hold an edge only
/// if its bounding box, grown by the tolerance, holds the edge's midpoint, so each edge is
/// tested against the triangles registered in its midpoint's cell of a uniform grid (the
/// cells each grown box overlaps, found by sorting (cell, triangle) pairs: O(n log n) for n
/// triangles) plus the few triangles too large for the grid (walls, floors spanning more than
/// kMaxCellsPerTriangle cells), instead of against every triangle. The cell of a point is a
/// monotone function of its coordinates, so the cell of any midpoint inside a grown box is
/// one the box was registered in: the same triangles pass the box test as in a scan of all.
class SealingSurfaces {
 public:
  explicit SealingSurfaces(const Mesh& mesh) : mesh_(mesh) {
    growBoxes();
    chooseCells();
    registerTriangles();
  }

  bool seal(const DiffractionEdge& e) const {
    const glm::vec3 mid = 0.5f * (e.a + e.b);
    const uint64_t key = keyOf(cellOf(mid));
    const auto cell =
        std::equal_range(cells_.begin(), cells_.end(), CellEntry{key, 0},
                         [](const CellEntry& x, const CellEntry& y) { return x.key < y.key; });
    for (auto it = cell.first; it != cell.second; ++it)
      if (holdsMidpoint(it->triangle, e, mid)) return true;
    for (const uint32_t t : large_)
      if (holdsMidpoint(t, e, mid)) return true;
    return false;
  }

 private:
  static constexpr float kTol = 1e-3f;  // m
  static constexpr int64_t kMaxCellsPerTriangle = 64;
  static constexpr int64_t kMaxCellsPerAxis = int64_t(1) << 20;  // 21 bits of a key each

  struct CellEntry {
    uint64_t key;
    uint32_t triangle;
  };

  /// Each triangle's bounding box grown by the tolerance, and the box of them all.
  void growBoxes() {
    lo_.reserve(mesh_.triangles.size());
    hi_.reserve(mesh_.triangles.size());
    for (const auto& tr : mesh_.triangles) {
      const glm::vec3 p0 = mesh_.vertices[tr[0]], p1 = mesh_.vertices[tr[1]],
                      p2 = mesh_.vertices[tr[2]];
      lo_.push_back(glm::min(p0, glm::min(p1, p2)) - kTol);
      hi_.push_back(glm::max(p0, glm::max(p1, p2)) + kTol);
      origin_ = lo_.size() == 1 ? lo_.back() : glm::min(origin_, lo_.back());
      top_ = hi_.size() == 1 ? hi_.back() : glm::max(top_, hi_.back());
    }
  }

  /// Cubic cells twice the median triangle's largest extent, coarser if the grid would
  /// exceed kMaxCellsPerAxis along an axis.
  void chooseCells() {
    if (lo_.empty()) return;
    std::vector<float> extents(lo_.size());
    for (size_t t = 0; t < lo_.size(); ++t) {
      const glm::vec3 d = hi_[t] - lo_[t];
      extents[t] = std::max(d.x, std::max(d.y, d.z));
    }
    std::nth_element(extents.begin(), extents.begin() + ptrdiff_t(extents.size() / 2),
                     extents.end());
    const glm::vec3 span = top_ - origin_;
    const float widest = std::max(span.x, std::max(span.y, span.z));
    const float cell =
        std::max(2.f * extents[extents.size() / 2], widest / float(kMaxCellsPerAxis - 2));
    inverseCell_ = 1.f / std::max(cell, 4.f * kTol);
  }

  /// The grid cell holding p, each coordinate clamped to the grid: monotone in p.
  std::array<int64_t, 3> cellOf(const glm::vec3& p) const {
    std::array<int64_t, 3> c{};
    for (int k = 0; k < 3; ++k) {
      const float f = std::floor((p[k] - origin_[k]) * inverseCell_);
      c[size_t(k)] = std::clamp(int64_t(std::clamp(f, -1.f, float(kMaxCellsPerAxis))), int64_t(0),
                                kMaxCellsPerAxis - 1);
    }
    return c;
  }

  static uint64_t keyOf(const std::array<int64_t, 3>& c) {
    return uint64_t(c[0]) << 42 | uint64_t(c[1]) << 21 | uint64_t(c[2]);
  }

  /// Every triangle into the cells its grown box overlaps (or into large_), sorted by cell.
  void registerTriangles() {
    cells_.reserve(lo_.size() * 4);
    for (uint32_t t = 0; t < lo_.size(); ++t) {
      const auto a = cellOf(lo_[t]), b = cellOf(hi_[t]);
      if ((b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1) > kMaxCellsPerTriangle) {
        large_.push_back(t);
        continue;
      }
      for (int64_t x = a[0]; x <= b[0]; ++x)
        for (int64_t y = a[1]; y <= b[1]; ++y)
          for (int64_t z = a[2]; z <= b[2]; ++z) cells_.push_back({keyOf({x, y, z}), t});
    }
    std::sort(cells_.begin(), cells_.end(), [](const CellEntry& x, const CellEntry& y) {
      return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
    });
  }

  /// The box test, then whether triangle t holds the edge.
  bool holdsMidpoint(uint32_t t, const DiffractionEdge& e, const glm::vec3& mid) const {
    if (glm::any(glm::lessThan(mid, lo_[t])) || glm::any(glm::greaterThan(mid, hi_[t])))
      return false;
    return holds(mesh_.triangles[t], e, mid);
  }

  /// True if the triangle tr (not one of the edge's own faces) contains the edge.
  bool holds(const std::array<uint32_t, 3>& tr, const DiffractionEdge& e,
             const glm::vec3& mid) const {
    const glm::vec3 p0 = mesh_.vertices[tr[0]], p1 = mesh_.vertices[tr[1]],
                    p2 = mesh_.vertices[tr[2]];
    const glm::vec3 nrm = safeNormalize(glm::cross(p1 - p0, p2 - p0));
    if (glm::length(nrm) == 0.f) return false;
    if (std::abs(glm::dot(e.a - p0, nrm)) > kTol || std::abs(glm::dot(e.b - p0, nrm)) > kTol)
      return false;
    // Is the midpoint inside the triangle (edge functions, with tolerance)?
    const glm::vec3 q = mid - glm::dot(mid - p0, nrm) * nrm;
    const float w0 = glm::dot(glm::cross(p1 - p0, q - p0), nrm) / glm::length(p1 - p0);
    const float w1 = glm::dot(glm::cross(p2 - p1, q - p1), nrm) / glm::length(p2 - p1);
    const float w2 = glm::dot(glm::cross(p0 - p2, q - p2), nrm) / glm::length(p0 - p2);
    auto isVertex = [&](const glm::vec3& v) { return v == p0 || v == p1 || v == p2; };
    if (isVertex(e.a) && isVertex(e.b)) return false;  // one of the edge's own faces
    return w0 > -kTol && w1 > -kTol && w2 > -kTol;
  }

  const Mesh& mesh_;
  std::vector<glm::vec3> lo_, hi_;  ///< grown boxes, per triangle
  glm::vec3 origin_{0.f}, top_{0.f};
  float inverseCell_ = 1.f;       ///< 1 / cell size, 1/m
  std::vector<CellEntry> cells_;  ///< sorted by key
  std::vector<uint32_t> large_;   ///< triangles spanning more than kMaxCellsPerTriangle cells
};

/// Lexicographic order of the endpoints: a deterministic edge order (the hash map's is not).
bool edgeBefore(const DiffractionEdge& x, const DiffractionEdge& y) {
  if (x.a.x != y.a.x) return x.a.x < y.a.x;
  if (x.a.y != y.a.y) return x.a.y < y.a.y;
  if (x.a.z != y.a.z) return x.a.z < y.a.z;
  if (x.b.x != y.b.x) return x.b.x < y.b.x;
  if (x.b.y != y.b.y) return x.b.y < y.b.y;
  return x.b.z < y.b.z;
}

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

/// Fills p's slit from its gap width: the slit's centre line runs along the edge, half the
/// width across the mouth; its stationary point, legs and angles as engine/slit.h defines them.
void makeSlit(const glm::vec3& source, const glm::vec3& L, EdgePath& p) {
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
  sp.zFrom = -double(z0);
  sp.zTo = double(e.length) - double(z0);
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
      makeSlit(source, L, p);
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
};

/// |p|^2 of the direct sound (amplitude directAmplitude at directDistance, m) plus every
/// path, averaged over band b's frequencies. A path through a gap adds its slit's field
/// (engine/slit.h) with weight s = slitWeight(k_t w, aspect) and its edge's UTD field with
/// weight 1 - s.
double bandMeanSquare(int b, const std::vector<EdgePath>& paths, const PathGains& gains,
                      double directAmplitude, float directDistance, float speedOfSound) {
  double acc = 0.0;
  for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
    const double k = 2.0 * kPi * diffractionFrequencyHz(b, i) / speedOfSound;
    C p = directAmplitude * pathPhasor(k * double(directDistance));
    C diffracted(0.0, 0.0);
    for (size_t j = 0; j < paths.size(); ++j) {
      const EdgePath& q = paths[j];
      double amplitude = gains.utd[j];
      if (q.gapWidth > 0.f) {
        const double s = slitWeight(k * q.slit.sinBeta * q.slit.width, q.slitAspect);
        if (s > 0.0 && q.slitOwner) p += s * gains.slit[j] * slitPressure(q.slit, k);
        if (s >= 1.0) continue;
        amplitude *= 1.0 - s;
      }
      const C d = utdScaled(q.terms, q.sums, q.prefactor, k * q.distanceParameter);
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
/// each path's pressure scaled by the square root of its energy weight (none when empty).
Bands coherentIntensity(const std::vector<EdgePath>& paths, const DirectSound& direct,
                        float speedOfSound, const Bands& airPerMetre,
                        const std::vector<Bands>& weights) {
  Bands intensity(0.f);
  PathGains gains{std::vector<double>(paths.size()), std::vector<double>(paths.size())};
  for (int b = 0; b < kNumBands; ++b) {
    for (size_t j = 0; j < paths.size(); ++j) {
      const double w = weights.empty() ? 1.0 : std::sqrt(double(weights[j][b]));
      gains.utd[j] = paths[j].spreading * std::exp(-0.5 * double(airPerMetre[b]) * paths[j].length);
      if (!weights.empty()) gains.utd[j] *= w;
      gains.slit[j] =
          w * std::exp(-0.5 * double(airPerMetre[b]) * (paths[j].slit.r + paths[j].slit.s));
    }
    const double directAmplitude =
        direct.visible ? std::sqrt(4.0 * kPi * double(direct.intensity[b])) : 0.0;
    const double meanSquare =
        bandMeanSquare(b, paths, gains, directAmplitude, direct.distance, speedOfSound);
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

EdgeDiffraction::EdgeDiffraction(const Mesh& mesh) {
  // Edges by position, not by index: an exporter may write a corner once per face.
  const std::vector<uint32_t> id = weldedVertexIds(mesh);
  const SealingSurfaces surfaces(mesh);
  for (const auto& [key, use] : edgeUses(mesh, id)) {
    DiffractionEdge e;
    if (makeEdge(mesh, id, key, use, e) && !surfaces.seal(e)) edges_.push_back(e);
  }
  std::sort(edges_.begin(), edges_.end(), edgeBefore);
}

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
  direct.intensity = coherentIntensity(paths, coherent, speedOfSound, airPerMetre,
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
