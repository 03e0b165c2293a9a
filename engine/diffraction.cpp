#include "engine/diffraction.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <numbers>
#include <unordered_map>

namespace dpc {

namespace {

using C = std::complex<double>;
constexpr double kPi = std::numbers::pi;

/// Fresnel integrals C(z), S(z) from the auxiliary functions f, g (Abramowitz & Stegun
/// 7.3.32-33; absolute error below 2e-3 for z >= 0).
void fresnel(double z, double& c, double& s) {
  const double f = (1.0 + 0.926 * z) / (2.0 + 1.792 * z + 3.104 * z * z);
  const double g = 1.0 / (2.0 + 4.142 * z + 3.492 * z * z + 6.670 * z * z * z);
  const double a = 0.5 * kPi * z * z;
  c = 0.5 + f * std::sin(a) - g * std::cos(a);
  s = 0.5 - f * std::cos(a) - g * std::sin(a);
}

/// Kouyoumjian-Pathak transition function F(X) = 2j sqrt(X) e^{jX} int_sqrt(X)^inf e^{-jt^2} dt.
C transition(double x) {
  x = std::max(x, 0.0);
  const double sx = std::sqrt(x);
  double c, s;
  fresnel(sx * std::sqrt(2.0 / kPi), c, s);
  // int_u^inf e^{-j t^2} dt = sqrt(pi/2) [(1/2 - C) - j (1/2 - S)] at u = sqrt(X).
  const C tail = std::sqrt(kPi / 2.0) * C(0.5 - c, -(0.5 - s));
  return 2.0 * C(0.0, 1.0) * sx * std::exp(C(0.0, x)) * tail;
}

/// One of the four UTD terms: cot((pi + sign x) / 2n) F(k L a_sign(x)).
C term(double n, double kl, double x, int sign) {
  // At a shadow or reflection boundary cot is infinite and F zero; their product is finite
  // and continuous. Evaluate a hair off the boundary (both factors at the same angle).
  if (std::abs(std::sin((kPi + sign * x) / (2.0 * n))) < 1e-6) x += 1e-5;
  const double nRound = std::round((x + sign * kPi) / (2.0 * n * kPi));
  const double ang = (2.0 * n * kPi * nRound - x) / 2.0;
  const double a = 2.0 * std::cos(ang) * std::cos(ang);
  const double arg = (kPi + sign * x) / (2.0 * n);
  return (std::cos(arg) / std::sin(arg)) * transition(kl * a);
}

glm::vec3 safeNormalize(const glm::vec3& v) {
  const float l = glm::length(v);
  return l > 0.f ? v / l : glm::vec3(0.f);
}

}  // namespace

Complex utdCoefficient(double n, double k, double phi, double phiSource, double sinBeta0,
                       double L) {
  const double kl = k * L;
  const double dm = phi - phiSource, dp = phi + phiSource;
  const C sum = term(n, kl, dm, +1) + term(n, kl, dm, -1) + term(n, kl, dp, +1) +
                term(n, kl, dp, -1);  // hard wedge: reflected terms with +
  const C pre = -std::exp(C(0.0, -kPi / 4.0)) /
                (2.0 * n * std::sqrt(2.0 * kPi * k) * std::max(sinBeta0, 1e-9));
  const C d = pre * sum;
  return {d.real(), d.imag()};
}

EdgeDiffraction::EdgeDiffraction(const Mesh& mesh) {
  // Undirected edge -> the triangles using it (first two) and the count.
  struct Use {
    uint32_t tri[2]{};
    int count = 0;
  };
  std::unordered_map<uint64_t, Use> uses;
  uses.reserve(mesh.triangles.size() * 3);
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) {
      const uint64_t u = mesh.triangles[t][size_t(i)], v = mesh.triangles[t][size_t((i + 1) % 3)];
      Use& e = uses[u < v ? (u << 32 | v) : (v << 32 | u)];
      if (e.count < 2) e.tri[e.count] = t;
      ++e.count;
    }
  auto normalOf = [&](uint32_t t) {
    const auto& tr = mesh.triangles[t];
    return safeNormalize(glm::cross(mesh.vertices[tr[1]] - mesh.vertices[tr[0]],
                                    mesh.vertices[tr[2]] - mesh.vertices[tr[0]]));
  };
  auto inward = [&](uint32_t t, uint32_t ia, uint32_t ib, const glm::vec3& dir) {
    // In-plane unit vector of triangle t from the edge (ia, ib) toward its third vertex.
    const auto& tr = mesh.triangles[t];
    uint32_t third = tr[0];
    for (uint32_t v : tr)
      if (v != ia && v != ib) third = v;
    glm::vec3 w = mesh.vertices[third] - mesh.vertices[ia];
    w -= glm::dot(w, dir) * dir;
    return safeNormalize(w);
  };
  // An edge lying in another triangle (a partition's rim along the floor, a box standing on
  // it) is sealed by that surface: no wedge of air around it. Load time, edges x triangles.
  std::vector<glm::vec3> boxLo, boxHi;
  boxLo.reserve(mesh.triangles.size());
  boxHi.reserve(mesh.triangles.size());
  for (const auto& tr : mesh.triangles) {
    const glm::vec3 p0 = mesh.vertices[tr[0]], p1 = mesh.vertices[tr[1]], p2 = mesh.vertices[tr[2]];
    boxLo.push_back(glm::min(p0, glm::min(p1, p2)));
    boxHi.push_back(glm::max(p0, glm::max(p1, p2)));
  }
  auto liesOnSurface = [&](const DiffractionEdge& e) {
    constexpr float kTol = 1e-3f;  // m
    const glm::vec3 mid = 0.5f * (e.a + e.b);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
      // Cheap reject: the midpoint must lie in the triangle's box (grown by the tolerance).
      if (glm::any(glm::lessThan(mid, boxLo[t] - kTol)) ||
          glm::any(glm::greaterThan(mid, boxHi[t] + kTol)))
        continue;
      const auto& tr = mesh.triangles[t];
      const glm::vec3 p0 = mesh.vertices[tr[0]], p1 = mesh.vertices[tr[1]],
                      p2 = mesh.vertices[tr[2]];
      const glm::vec3 nrm = safeNormalize(glm::cross(p1 - p0, p2 - p0));
      if (glm::length(nrm) == 0.f) continue;
      if (std::abs(glm::dot(e.a - p0, nrm)) > kTol || std::abs(glm::dot(e.b - p0, nrm)) > kTol)
        continue;
      // Is the midpoint inside the triangle (edge functions, with tolerance)?
      const glm::vec3 q = mid - glm::dot(mid - p0, nrm) * nrm;
      const float w0 = glm::dot(glm::cross(p1 - p0, q - p0), nrm) / glm::length(p1 - p0);
      const float w1 = glm::dot(glm::cross(p2 - p1, q - p1), nrm) / glm::length(p2 - p1);
      const float w2 = glm::dot(glm::cross(p0 - p2, q - p2), nrm) / glm::length(p0 - p2);
      auto isVertex = [&](const glm::vec3& v) { return v == p0 || v == p1 || v == p2; };
      if (isVertex(e.a) && isVertex(e.b)) continue;  // one of the edge's own faces
      if (w0 > -kTol && w1 > -kTol && w2 > -kTol) return true;
    }
    return false;
  };
  for (const auto& [key, use] : uses) {
    if (use.count > 2) continue;  // non-manifold: no wedge defined
    const uint32_t ia = uint32_t(key >> 32), ib = uint32_t(key & 0xffffffffu);
    DiffractionEdge e;
    e.a = mesh.vertices[ia];
    e.b = mesh.vertices[ib];
    e.length = glm::length(e.b - e.a);
    if (!(e.length > 0.f)) continue;
    e.direction = (e.b - e.a) / e.length;
    e.face0 = inward(use.tri[0], ia, ib, e.direction);
    e.normal0 = normalOf(use.tri[0]);
    if (glm::length(e.face0) == 0.f || glm::length(e.normal0) == 0.f) continue;
    if (use.count == 1) {
      e.open = float(2.0 * kPi);  // half-plane: one wedge of 2 pi
    } else {
      // Angle of face 1 from face 0, turning toward normal0. Which of the two wedges
      // (open, 2 pi - open) holds air is decided per frame by where the source is, so the
      // mesh's winding does not matter.
      const glm::vec3 f1 = inward(use.tri[1], ia, ib, e.direction);
      double ang = std::atan2(double(glm::dot(f1, e.normal0)), double(glm::dot(f1, e.face0)));
      if (ang < 0) ang += 2.0 * kPi;
      e.open = float(ang);
      if (std::abs(ang - kPi) < 0.05 * kPi) continue;  // flat: no wedge
    }
    if (!liesOnSurface(e)) edges_.push_back(e);
  }
  // Deterministic order (the hash map's is not).
  std::sort(edges_.begin(), edges_.end(), [](const DiffractionEdge& x, const DiffractionEdge& y) {
    if (x.a.x != y.a.x) return x.a.x < y.a.x;
    if (x.a.y != y.a.y) return x.a.y < y.a.y;
    if (x.a.z != y.a.z) return x.a.z < y.a.z;
    if (x.b.x != y.b.x) return x.b.x < y.b.x;
    if (x.b.y != y.b.y) return x.b.y < y.b.y;
    return x.b.z < y.b.z;
  });
}

size_t EdgeDiffraction::apply(const Geometry& geometry, const glm::vec3& source,
                              const ListenerSphere& listener, float speedOfSound,
                              const Bands& airPerMetre, DirectSound& direct) const {
  struct Path {
    double r, s, phiS, phiL, n, sinBeta0;
  };
  std::vector<Path> paths;
  const glm::vec3 L = listener.position;
  constexpr float kLegEpsilon = 1e-3f;  // m: keeps occlusion tests off the edge's own faces
  size_t used = 0;
  float shortest = direct.visible ? direct.distance : 1e30f;
  glm::vec3 shortestDir = direct.direction;
  for (const DiffractionEdge& e : edges_) {
    // Stationary point: unfold both points about the edge; Q divides the along-edge
    // separation in the ratio of their distances from the edge line.
    const glm::vec3 ps = source - e.a, pl = L - e.a;
    const float ts = glm::dot(ps, e.direction), tl = glm::dot(pl, e.direction);
    const float rs = glm::length(ps - ts * e.direction), rl = glm::length(pl - tl * e.direction);
    if (!(rs > 1e-4f) || !(rl > 1e-4f)) continue;
    const float t = ts + (tl - ts) * rs / (rs + rl);
    if (!(t > 0.f && t < e.length)) continue;
    const glm::vec3 q = e.a + t * e.direction;
    const glm::vec3 toQ = q - source, toL = L - q;
    const float r = glm::length(toQ), s = glm::length(toL);
    if (!(r > kLegEpsilon && s > kLegEpsilon)) continue;
    // Angles from face 0 in the plane perpendicular to the edge, in [0, 2 pi).
    auto angleOf = [&](const glm::vec3& p) {
      const glm::vec3 v = p - q;
      double a = std::atan2(double(glm::dot(v, e.normal0)), double(glm::dot(v, e.face0)));
      return a < 0 ? a + 2.0 * kPi : a;
    };
    double phiS = angleOf(source);
    double phiL = angleOf(L);
    // The source's wedge is the air wedge: [0, open] or, measured from face 0 the other way,
    // [0, 2 pi - open]. The listener must be in it too; wedges narrower than about pi cannot
    // shadow (a room's inner corner seen from inside).
    double wedge = double(e.open);
    if (phiS > wedge) {
      wedge = 2.0 * kPi - wedge;
      phiS = 2.0 * kPi - phiS;
      phiL = 2.0 * kPi - phiL;
    }
    if (!(phiL > 0.0 && phiL < wedge) || wedge <= 1.05 * kPi) continue;
    // On the shadow boundary itself (|phi - phi'| = pi) the occlusion test that decided
    // direct.visible and the UTD's side of the boundary could disagree by rounding; put the
    // listener 1e-4 rad on the side the direct sound's visibility says.
    constexpr double kBoundary = 1e-4;
    const double dphi = phiL - phiS;
    if (std::abs(std::abs(dphi) - kPi) < kBoundary)
      phiL = phiS + std::copysign(direct.visible ? kPi - kBoundary : kPi + kBoundary, dphi);
    // Both legs clear (the listener sphere itself is not geometry).
    if (geometry.occluded(source, toQ / r, kLegEpsilon, r - kLegEpsilon)) continue;
    if (geometry.occluded(q, toL / s, kLegEpsilon, s - kLegEpsilon)) continue;
    const double sinB = double(glm::length(glm::cross(toQ / r, e.direction)));
    Path& p = paths.emplace_back();
    ++used;
    p.r = r;
    p.s = s;
    p.phiS = phiS;
    p.phiL = phiL;
    p.n = wedge / kPi;
    p.sinBeta0 = sinB;
    if (r + s < shortest) {
      shortest = r + s;
      shortestDir = -toL / s;
    }
  }
  if (used == 0) return 0;
  // Band energy of the coherent sum, averaged over kFrequencies log-spaced per octave.
  constexpr int kFrequencies = 16;
  Bands intensity(0.f);
  for (int b = 0; b < kNumBands; ++b) {
    double acc = 0.0;
    for (int i = 0; i < kFrequencies; ++i) {
      const double f = bandCentreExactHz(b) * std::exp2((i + 0.5) / kFrequencies - 0.5);
      const double k = 2.0 * kPi * f / speedOfSound;
      C p(0.0, 0.0);
      if (direct.visible) {
        const double amp = std::sqrt(4.0 * kPi * double(direct.intensity[b]));
        p += amp * std::exp(C(0.0, -k * double(direct.distance)));
      }
      for (size_t j = 0; j < used; ++j) {
        const Path& q = paths[j];
        const double len = q.r + q.s;
        const double Lp = q.r * q.s * q.sinBeta0 * q.sinBeta0 / len;
        const Complex d = utdCoefficient(q.n, k, q.phiL, q.phiS, q.sinBeta0, Lp);
        const double amp =
            std::sqrt(std::exp(-double(airPerMetre[b]) * len)) / q.r * std::sqrt(q.r / (q.s * len));
        p += amp * C(d.re, d.im) * std::exp(C(0.0, -k * len));
      }
      acc += std::norm(p);
    }
    intensity[b] = float(acc / kFrequencies / (4.0 * kPi));
  }
  direct.intensity = intensity;
  direct.visible = true;
  direct.distance = shortest;
  direct.delaySeconds = shortest / speedOfSound;
  direct.direction = shortestDir;
  return used;
}

}  // namespace dpc
