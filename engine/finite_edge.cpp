#include "engine/finite_edge.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <unordered_map>

#include "engine/diffraction_edges.h"

namespace dpc {

namespace {

constexpr double kPi = std::numbers::pi;

/// Whether edge y continues edge x along its line as the same wedge: parallel, y's ends on x's
/// line, and its faces in the same planes at the same angle (surfaces split by the mesh's
/// seams, or two bodies meeting end to end in line, make one edge).
bool continues(const DiffractionEdge& x, const DiffractionEdge& y) {
  constexpr float kParallel = 0.9999f, kOnLine = 1e-4f, kSameFace = 0.999f, kSameOpen = 1e-3f;
  if (std::abs(glm::dot(x.direction, y.direction)) < kParallel) return false;
  for (const glm::vec3& p : {y.a, y.b}) {
    const glm::vec3 v = p - x.a;
    if (glm::length(v - glm::dot(v, x.direction) * x.direction) > kOnLine) return false;
  }
  if (std::abs(x.open - y.open) > kSameOpen) return false;
  if (glm::dot(x.face0, y.face0) > kSameFace && glm::dot(x.normal0, y.normal0) > kSameFace)
    return true;
  // y's face 0 is x's face 1 (its faces listed the other way round): the same wedge.
  const glm::vec3 face1 = std::cos(x.open) * x.face0 + std::sin(x.open) * x.normal0;
  return glm::dot(face1, y.face0) > kSameFace;
}

/// A key for an endpoint, exact to 0.1 mm (welded meshes share their corners exactly).
uint64_t pointKey(const glm::vec3& p) {
  auto q = [](float v) { return uint64_t(int64_t(std::lround(double(v) * 1e4)) & 0x1fffff); };
  return q(p.x) | q(p.y) << 21 | q(p.z) << 42;
}

/// How far edge i's run goes on past its end `from` (m) in the sense `sense` (+1 past b, -1
/// past a), walking the edges that continue it.
float runBeyond(const std::vector<DiffractionEdge>& edges,
                const std::unordered_multimap<uint64_t, uint32_t>& atPoint, uint32_t i,
                glm::vec3 from, float sense) {
  float extra = 0.f;
  for (size_t step = 0; step < edges.size(); ++step) {  // at most every edge once
    bool found = false;
    const auto [lo, hi] = atPoint.equal_range(pointKey(from));
    for (auto it = lo; it != hi && !found; ++it) {
      const DiffractionEdge& y = edges[it->second];
      if (it->second == i || !continues(edges[i], y)) continue;
      const glm::vec3 next = glm::distance(y.a, from) < glm::distance(y.b, from) ? y.b : y.a;
      if (!(sense * glm::dot(next - from, edges[i].direction) > 0.f)) continue;  // runs back
      extra += y.length;
      from = next;
      found = true;
    }
    if (!found) break;
  }
  return extra;
}

/// Per BTM term, its amplitude |sin(nu psi) / (cosh(nu eta) - cos(nu psi))| at eta (cosh eta =
/// coshEta).
std::array<double, 4> btmTerms(double coshEta, double nu, const std::array<double, 4>& psi) {
  const double c = std::cosh(nu * std::acosh(std::max(coshEta, 1.0)));
  std::array<double, 4> out{};
  for (size_t i = 0; i < 4; ++i)
    out[i] = std::abs(std::sin(nu * psi[i])) / std::max(c - std::cos(nu * psi[i]), 1e-12);
  return out;
}

/// G(x) = int_x^inf e^{-j t^2} dt over the whole line's integral, x >= 0.
std::complex<double> fresnelTail(double x) {
  const std::complex<double> whole = std::sqrt(kPi) * std::polar(1.0, -0.25 * kPi);
  return 0.5 - fresnelIntegral(x) / whole;
}

}  // namespace

void setEdgeRuns(std::vector<DiffractionEdge>& edges) {
  std::unordered_multimap<uint64_t, uint32_t> atPoint;
  for (uint32_t i = 0; i < uint32_t(edges.size()); ++i) {
    atPoint.emplace(pointKey(edges[i].a), i);
    atPoint.emplace(pointKey(edges[i].b), i);
  }
  std::vector<std::array<float, 2>> runs(edges.size());
  for (uint32_t i = 0; i < uint32_t(edges.size()); ++i)
    runs[i] = {-runBeyond(edges, atPoint, i, edges[i].a, -1.f),
               edges[i].length + runBeyond(edges, atPoint, i, edges[i].b, 1.f)};
  for (size_t i = 0; i < edges.size(); ++i) {
    edges[i].runFrom = runs[i][0];
    edges[i].runTo = runs[i][1];
  }
}

void markFreeEnds(const SurfaceBodies& bodies, const std::vector<std::vector<uint32_t>>& near,
                  std::vector<DiffractionEdge>& edges) {
  constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  auto bodyOf = [&](uint32_t s) { return s < bodies.body.size() ? bodies.body[s] : kNone; };
  std::vector<bool> mounted(bodies.closed.size(), false);  // a body beside another's edge
  for (size_t i = 0; i < edges.size() && i < near.size(); ++i)
    for (uint32_t j : near[i]) {
      const uint32_t b = bodyOf(edges[i].surfaces[0]);
      if (b != kNone && b < mounted.size() && bodyOf(edges[j].surfaces[0]) != b) mounted[b] = true;
    }
  for (DiffractionEdge& e : edges) {
    const uint32_t b = bodyOf(e.surfaces[0]);
    e.freeEnds = isFreeEdge(e) && std::isfinite(e.runFrom) && std::isfinite(e.runTo) &&
                 b != kNone && b < mounted.size() && !mounted[b] &&
                 smallBody(bodies, e.surfaces[0]);
  }
}

EdgeEnds edgeEnds(const DiffractionEdge& e, const glm::vec3& q, const glm::vec3& source,
                  const glm::vec3& L, double phiS, double phiL, double wedge,
                  const std::array<UtdTerm, 4>& terms) {
  EdgeEnds out;
  if (!isFreeEdge(e)) return out;  // a wedge's edge: taken as infinite
  const glm::dvec3 dir(e.direction), Q(q), S(source), R(L);
  const double t = glm::dot(Q - glm::dvec3(e.a), dir);
  const double zs = glm::dot(S - Q, dir), zr = glm::dot(R - Q, dir);
  const double rs = glm::length(S - Q - zs * dir), rr = glm::length(R - Q - zr * dir);
  const double r = glm::length(S - Q), s = glm::length(R - Q);
  if (!(rs > 1e-6 && rr > 1e-6)) return out;
  out.zone = 0.5 * (rs / r) * (rs / r) * (r + s) / (r * s);
  const double nu = kPi / wedge;
  const std::array<double, 4> psi{kPi + (phiL - phiS), kPi - (phiL - phiS), kPi + (phiL + phiS),
                                  kPi - (phiL + phiS)};
  const std::array<double, 4> atQ = btmTerms(1.0, nu, psi);
  out.at = {float(double(e.runFrom) - t), float(double(e.runTo) - t)};
  for (size_t end = 0; end < 2; ++end) {
    const double z = double(out.at[end]);
    std::array<double, 4> atEnd{};  // none at an infinite end
    double ml = 1.0;
    if (std::isfinite(z)) {
      const double m = glm::length(S - Q - z * dir), l = glm::length(R - Q - z * dir);
      atEnd = btmTerms((m * l + (z - zs) * (z - zr)) / (rs * rr), nu, psi);
      ml = m * l;
    }
    out.terms[end] = terms;
    for (size_t i = 0; i < 4; ++i) {
      const double w = atQ[i] > 0.0 ? atEnd[i] * r * s / (atQ[i] * ml) : 0.0;
      out.terms[end][i].cot *= std::clamp(w, 0.0, 1.0);
    }
    out.sums[end] = utdTermSums(out.terms[end]);
  }
  return out;
}

std::array<std::complex<double>, 2> endTails(const EdgeEnds& ends, double k) {
  const double scale = std::sqrt(k * ends.zone);
  std::array<std::complex<double>, 2> out{};
  for (size_t i = 0; i < 2; ++i)
    if (std::isfinite(ends.at[i])) out[i] = fresnelTail(scale * std::abs(double(ends.at[i])));
  return out;
}

std::complex<double> withEnds(const EdgeEnds& ends, const std::array<std::complex<double>, 2>& g,
                              std::complex<double> d,
                              const std::array<std::complex<double>, 2>& dEnds) {
  if (!ends.outside) return d - g[1] * dEnds[1] - g[0] * dEnds[0];
  const size_t near = std::abs(ends.at[0]) < std::abs(ends.at[1]) ? 0 : 1;
  return g[near] * dEnds[near] - g[1 - near] * dEnds[1 - near];
}

std::complex<double> finiteEdgeFactor(const EdgeEnds& ends, double k, std::complex<double> d,
                                      const std::array<std::complex<double>, 2>& dEnds) {
  if (!ends.finite() || std::abs(d) == 0.0) return 1.0;
  return withEnds(ends, endTails(ends, k), d, dEnds) / d;
}

}  // namespace dpc
