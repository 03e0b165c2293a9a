// The first-order diffraction of finite thin rigid edges by the Biot-Tolstoy-Medwin secondary
// source model, for tests: an oracle that shares nothing with the engine's UTD sum and its
// finite-edge factor (engine/finite_edge.h). Each point z of the edge radiates
//
//   dH = -(nu / 4 pi) beta(eta) / (m l) e^{-j k (m + l)} dz,   nu = 1/2 for a thin screen,
//   beta = sum over the four signs of sin(nu psi) / (cosh(nu eta) - cos(nu psi)),
//   psi = pi +- theta_S +- theta_R,  cosh eta = (m l + (z - z_S)(z - z_R)) / (r_S r_R)
//
// (U. P. Svensson, R. I. Fred, J. Vanderkooy, "An analytic secondary source model of edge
// diffraction impulse responses", JASA 106(5), 1999, eqs. 8-10), m and l the distances from the
// source and the receiver to that point, r and z their cylindrical coordinates about the edge,
// theta their angles from the screen's face; the direct sound is e^{-jkd} / d. The integral is
// taken by the midpoint rule at steps of at most a fortieth of the shortest wavelength asked
// for, so receivers must stay off the shadow and reflection boundaries, where the integrand
// peaks at one point.
//
// Used by tests only (single thread, allocates nothing beyond the returned values).
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <numbers>
#include <vector>

namespace dpc::test {

/// A thin rigid screen's edge from a to b (m); `face` the unit vector in the screen's plane,
/// square to the edge, pointing from the edge into the screen.
struct ThinEdge {
  glm::dvec3 a, b, face;
};

/// The first-order field of `edge` at the receiver R from a unit point source at S, at
/// frequency f (Hz), speed of sound c (m/s): pressure re a free field of 1/r.
inline std::complex<double> btmThinEdge(const ThinEdge& edge, const glm::dvec3& S,
                                        const glm::dvec3& R, double f, double c) {
  constexpr double kPi = std::numbers::pi, nu = 0.5;
  const double length = glm::length(edge.b - edge.a);
  const glm::dvec3 e = (edge.b - edge.a) / length, n = glm::cross(e, edge.face);
  auto cylinder = [&](const glm::dvec3& p, double& r, double& theta, double& z) {
    z = glm::dot(p - edge.a, e);
    const glm::dvec3 rho = p - edge.a - z * e;
    r = glm::length(rho);
    theta = std::atan2(glm::dot(rho, n), glm::dot(rho, edge.face));
    if (theta < 0.0) theta += 2.0 * kPi;
  };
  double rs = 0, ts = 0, zs = 0, rr = 0, tr = 0, zr = 0;
  cylinder(S, rs, ts, zs);
  cylinder(R, rr, tr, zr);
  const double psi[4] = {kPi + ts + tr, kPi + ts - tr, kPi - ts + tr, kPi - ts - tr};
  const double k = 2.0 * kPi * f / c;
  const int steps = std::max(64, int(std::ceil(length / (c / f / 40.0))));
  const double dz = length / steps;
  std::complex<double> sum = 0.0;
  for (int i = 0; i < steps; ++i) {
    const double z = (i + 0.5) * dz;
    const glm::dvec3 p = edge.a + z * e;
    const double m = glm::length(S - p), l = glm::length(R - p);
    const double coshEta = std::max((m * l + (z - zs) * (z - zr)) / (rs * rr), 1.0);
    const double c2 = std::cosh(nu * std::acosh(coshEta));
    double beta = 0.0;
    for (double a : psi) beta += std::sin(nu * a) / (c2 - std::cos(nu * a));
    sum += -(nu / (4.0 * kPi)) * beta / (m * l) * dz * std::polar(1.0, -k * (m + l));
  }
  return sum;
}

/// The band level (dB re the free field) of the direct sound (when `direct`) plus the
/// first-order fields of `edges`, |p|^2 averaged over 16 log-spaced frequencies across the
/// octave centred on fc (Hz), as the engine averages its coherent sum.
inline double btmBandLevelDb(const std::vector<ThinEdge>& edges, const glm::dvec3& S,
                             const glm::dvec3& R, bool direct, double fc, double c) {
  const double d = glm::length(R - S);
  double mean = 0.0;
  for (int i = 0; i < 16; ++i) {
    const double f = fc * std::exp2((i + 0.5) / 16.0 - 0.5);
    std::complex<double> p =
        direct ? std::polar(1.0 / d, -2.0 * std::numbers::pi * f / c * d) : 0.0;
    for (const ThinEdge& edge : edges) p += btmThinEdge(edge, S, R, f, c);
    mean += std::norm(p) * d * d / 16.0;
  }
  return 10.0 * std::log10(mean);
}

/// The four edges of a rectangular thin plate (or of a rectangular hole in a thin wall:
/// `hole`) with corner c0 and sides u, v (m; c0, c0 + u, c0 + u + v, c0 + v).
inline std::vector<ThinEdge> rectangleEdges(const glm::dvec3& c0, const glm::dvec3& u,
                                            const glm::dvec3& v, bool hole) {
  const glm::dvec3 corners[4] = {c0, c0 + u, c0 + u + v, c0 + v};
  const glm::dvec3 centre = c0 + 0.5 * (u + v);
  std::vector<ThinEdge> out;
  for (int i = 0; i < 4; ++i) {
    const glm::dvec3 a = corners[i], b = corners[(i + 1) % 4], e = glm::normalize(b - a);
    glm::dvec3 in = centre - a;
    in = glm::normalize(in - glm::dot(in, e) * e);
    out.push_back({a, b, hole ? -in : in});
  }
  return out;
}

}  // namespace dpc::test
