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

#include "scene/mesh_topology.h"

namespace dpc {

namespace {

using C = std::complex<double>;
constexpr double kPi = std::numbers::pi;

// The Kouyoumjian-Pathak transition function F(X) = 2j sqrt(X) e^{jX} int_sqrt(X)^inf e^{-jt^2} dt
// (X >= 0), to about 2e-5 absolute everywhere, in three pieces.
constexpr double kTransitionSwitch = 12.0;  // asymptotic series from here on

/// F by the power series of int_0^u e^{-jt^2} dt = sum_m (-j)^m u^{2m+1} / (m! (2m+1)),
/// subtracted from its limit (sqrt(pi) / 2) e^{-j pi / 4}: exact to rounding for X below the
/// switch (cancellation costs at most 5 of 16 digits at X = 12). Up to ~55 terms: used to
/// fill the table below.
C transitionSeries(double x) {
  // Complex products written out: std::complex's operator* takes the slow, NaN-checking path.
  const double u = std::sqrt(x);
  // sum_m power_m / (2m + 1), power_m = u (-jX)^m / m!.
  double pRe = u, pIm = 0.0, iRe = 0.0, iIm = 0.0;
  for (int m = 0; m < 80; ++m) {
    const double w = 1.0 / double(2 * m + 1);
    const double tRe = pRe * w, tIm = pIm * w;
    iRe += tRe, iIm += tIm;
    // Past the largest term (m > X) stop once a term no longer changes the sum.
    if (m > x && tRe * tRe + tIm * tIm < 1e-34 * (1.0 + iRe * iRe + iIm * iIm)) break;
    const double g = -x / double(m + 1);  // multiply by j g
    const double re = -pIm * g, im = pRe * g;
    pRe = re, pIm = im;
  }
  // limit = (sqrt(pi) / 2) e^{-j pi / 4}; F = 2j u e^{jX} (limit - integral).
  const double half = 0.5 * std::sqrt(kPi) * std::numbers::sqrt2 / 2.0;
  const double dRe = half - iRe, dIm = -half - iIm;
  const double cx = std::cos(x), sx = std::sin(x);
  const double eRe = cx * dRe - sx * dIm, eIm = cx * dIm + sx * dRe;
  return {-2.0 * u * eIm, 2.0 * u * eRe};
}

/// G(u) = F(u^2) below the switch, tabulated with its derivative G'(u) = F / u + 2ju (F - 1)
/// (from F'(X) = F (1 / 2X + j) - j; G'(0) = sqrt(pi) e^{j pi / 4}) at steps of 1/64 in u and
/// interpolated by cubic Hermite: G is smooth in u = sqrt(X), not in X. Interpolation error
/// below 5e-9 (checked against the series over X in [0, 12) at steps of 1e-4).
class TransitionTable {
 public:
  static constexpr double kStep = 1.0 / 64.0;
  TransitionTable() {
    for (size_t i = 0; i < kSize; ++i) {
      const double u = double(i) * kStep;
      g_[i] = transitionSeries(u * u);
      dg_[i] = i == 0 ? std::sqrt(kPi) * std::exp(C(0.0, kPi / 4.0))
                      : g_[i] / u + C(0.0, 2.0 * u) * (g_[i] - 1.0);
      dg_[i] *= kStep;
    }
  }
  C operator()(double x) const {
    const double v = std::sqrt(x) / kStep;
    const size_t i = std::min(size_t(v), kSize - 2);
    const double t = v - double(i), t2 = t * t, t3 = t2 * t;
    const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2,
                 h11 = t3 - t2;
    return {
        h00 * g_[i].real() + h10 * dg_[i].real() + h01 * g_[i + 1].real() + h11 * dg_[i + 1].real(),
        h00 * g_[i].imag() + h10 * dg_[i].imag() + h01 * g_[i + 1].imag() +
            h11 * dg_[i + 1].imag()};
  }

 private:
  static constexpr size_t kSize = size_t(3.4641016 / kStep) + 3;  // u up to sqrt(12)
  std::array<C, kSize> g_, dg_;
};

/// F(X): the table below the switch; from X = 12 on the asymptotic series
/// F ~ sum_m (2m-1)!! / (-2jX)^m to m = 7, whose first omitted term is 2e-5 at X = 12 and falls
/// as X^-8 (Kouyoumjian & Pathak 1974 give its first terms). Both pieces agree at the switch
/// within that bound.
C transition(double x) {
  x = std::max(x, 0.0);
  if (x < kTransitionSwitch) {
    static const TransitionTable table;
    return table(x);
  }
  // t_m = t_{m-1} (2m - 1) / (-2jX) = t_{m-1} * j (2m - 1) / (2X).
  const double h = 0.5 / x;
  double sumRe = 1.0, sumIm = 0.0, tRe = 1.0, tIm = 0.0;
  for (int m = 1; m <= 7; ++m) {
    const double g = double(2 * m - 1) * h;
    const double re = -tIm * g, im = tRe * g;
    tRe = re, tIm = im;
    sumRe += tRe, sumIm += tIm;
  }
  return {sumRe, sumIm};
}

/// Frequency-independent parts of one UTD term cot((pi + sign x) / 2n) F(k L a_sign(x)):
/// the cotangent and a_sign(x) = 2 cos^2((2 pi n N - x) / 2), N the integer nearest
/// (x + sign pi) / (2 pi n).
struct TermGeometry {
  double cot = 0.0, a = 0.0;
};

TermGeometry termGeometry(double n, double x, int sign) {
  // At a shadow or reflection boundary cot is infinite and F zero; their product is finite
  // and continuous. Evaluate a hair off the boundary (both factors at the same angle).
  if (std::abs(std::sin((kPi + sign * x) / (2.0 * n))) < 1e-6) x += 1e-5;
  const double nRound = std::round((x + sign * kPi) / (2.0 * n * kPi));
  const double ang = (2.0 * n * kPi * nRound - x) / 2.0;
  const double arg = (kPi + sign * x) / (2.0 * n);
  return {std::cos(arg) / std::sin(arg), 2.0 * std::cos(ang) * std::cos(ang)};
}

/// The four terms of the hard-wedge coefficient (reflected terms with +) for phi, phi'.
std::array<TermGeometry, 4> wedgeTerms(double n, double phi, double phiSource) {
  const double dm = phi - phiSource, dp = phi + phiSource;
  return {termGeometry(n, dm, +1), termGeometry(n, dm, -1), termGeometry(n, dp, +1),
          termGeometry(n, dp, -1)};
}

/// The magnitude of D's prefactor without its 1 / sqrt(k): 1 / (2 n sqrt(2 pi) sin beta0).
double utdPrefactor(double n, double sinBeta0) {
  return 1.0 / (2.0 * n * std::sqrt(2.0 * kPi) * std::max(sinBeta0, 1e-9));
}

/// D sqrt(k) = -e^{-j pi/4} prefactor * sum of the four terms at k L = kl.
C utdScaled(const std::array<TermGeometry, 4>& terms, double prefactor, double kl) {
  double re = 0.0, im = 0.0;
  for (const TermGeometry& t : terms) {
    const C f = transition(kl * t.a);
    re += t.cot * f.real(), im += t.cot * f.imag();
  }
  // -e^{-j pi/4} = (-1 + j) / sqrt 2.
  const double g = prefactor / std::numbers::sqrt2;
  return {g * (-re - im), g * (re - im)};
}

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

/// One first-order edge path source -> Q -> listener: its frequency-independent parts.
struct EdgePath {
  double length;                      // r + s, m
  double distanceParameter;           // L = r s sin^2 beta0 / (r + s), m
  double spreading;                   // 1/r sqrt(r / (s (r + s))), 1/m
  double prefactor;                   // utdPrefactor(n, sin beta0)
  std::array<TermGeometry, 4> terms;  // frequency-independent parts of D
  float legs;                         // r + s in single precision, m
  glm::vec3 arrival;                  // unit vector from the listener toward Q
  glm::vec3 leaving;                  // unit vector from the source toward Q
};

/// Angles (radians, from face 0 in the plane perpendicular to the edge) of the source and the
/// listener seen from Q, and the air wedge's angle; false unless the listener is in the
/// source's wedge and that wedge is wider than about pi (narrower ones cannot shadow: a room's
/// inner corner seen from inside).
bool wedgeAngles(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& source,
                 const glm::vec3& L, bool directVisible, double& phiS, double& phiL,
                 double& wedge) {
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
  if (phiS > wedge) {
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
  double phiS = 0.0, phiL = 0.0, wedge = 0.0;
  if (!wedgeAngles(e, q, source, L, directVisible, phiS, phiL, wedge)) return false;
  if (tracer.occluded(TraceRay{source, toQ / r, kLegEpsilon, r - kLegEpsilon})) return false;
  if (tracer.occluded(TraceRay{q, toL / s, kLegEpsilon, s - kLegEpsilon})) return false;
  const double sinB = double(glm::length(glm::cross(toQ / r, e.direction)));
  p.length = double(r) + double(s);
  p.distanceParameter = double(r) * double(s) * sinB * sinB / p.length;
  p.spreading = 1.0 / double(r) * std::sqrt(double(r) / (double(s) * p.length));
  p.prefactor = utdPrefactor(wedge / kPi, sinB);
  p.terms = wedgeTerms(wedge / kPi, phiL, phiS);
  p.legs = r + s;
  p.arrival = -toL / s;
  p.leaving = toQ / r;
  return true;
}

/// |p|^2 of the direct sound (amplitude directAmplitude at directDistance, m) plus every
/// path (per-path band amplitude in `amplitude`), averaged over band b's frequencies.
double bandMeanSquare(int b, const std::vector<EdgePath>& paths,
                      const std::vector<double>& amplitude, double directAmplitude,
                      float directDistance, float speedOfSound) {
  double acc = 0.0;
  for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
    const double k = 2.0 * kPi * diffractionFrequencyHz(b, i) / speedOfSound;
    C p = directAmplitude * std::polar(1.0, -k * double(directDistance));
    C diffracted(0.0, 0.0);
    for (size_t j = 0; j < paths.size(); ++j) {
      const EdgePath& q = paths[j];
      const C d = utdScaled(q.terms, q.prefactor, k * q.distanceParameter);
      const double c = std::cos(k * q.length), sn = std::sin(k * q.length);
      // amplitude * d * e^{-jkl}
      diffracted += amplitude[j] * C(d.real() * c + d.imag() * sn, d.imag() * c - d.real() * sn);
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
  std::vector<double> amplitude(paths.size());
  for (int b = 0; b < kNumBands; ++b) {
    // Per path and band: spreading times the air's pressure attenuation sqrt(exp(-m l)).
    for (size_t j = 0; j < paths.size(); ++j) {
      amplitude[j] = paths[j].spreading * std::exp(-0.5 * double(airPerMetre[b]) * paths[j].length);
      if (!weights.empty()) amplitude[j] *= std::sqrt(double(weights[j][b]));
    }
    const double directAmplitude =
        direct.visible ? std::sqrt(4.0 * kPi * double(direct.intensity[b])) : 0.0;
    const double meanSquare =
        bandMeanSquare(b, paths, amplitude, directAmplitude, direct.distance, speedOfSound);
    intensity[b] = float(meanSquare / (4.0 * kPi));
  }
  return intensity;
}

}  // namespace

Complex utdCoefficient(double n, double k, double phi, double phiSource, double sinBeta0,
                       double L) {
  const C d =
      utdScaled(wedgeTerms(n, phi, phiSource), utdPrefactor(n, sinBeta0), k * L) / std::sqrt(k);
  return {d.real(), d.imag()};
}

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
                              const Directivity& directivity, const glm::vec3& forward) const {
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
  if (paths.empty()) return 0;
  DirectSound coherent = direct;
  coherent.visible = lineOfSight;
  const Bands through = lineOfSight || !direct.visible ? Bands(0.f) : direct.intensity;
  direct.intensity = coherentIntensity(paths, coherent, speedOfSound, airPerMetre,
                                       leavingWeights(paths, directivity, forward)) +
                     through;
  direct.visible = true;
  direct.distance = shortest;
  direct.delaySeconds = shortest / speedOfSound;
  direct.direction = shortestDir;
  return paths.size();
}

}  // namespace dpc
