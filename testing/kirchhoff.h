// The Kirchhoff (physical-optics) integral of a sound reflection off rigid rectangles, by
// quadrature: the tests' independent oracle for the engine's small-face reflections
// (engine/small_reflectors.h, engine/reflection_scattering.h). Test code only.
#pragma once

#include <cmath>
#include <complex>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <numbers>
#include <vector>

#include "common/bands.h"

namespace dpc::test {

/// The speed of sound the oracle takes, m/s.
inline constexpr double kKirchhoffC = 343.0;

/// One rigid rectangle: corner o, edges u and v (m).
struct Rect {
  glm::dvec3 o, u, v;
};

/// |p / p_image|^2 at frequency f (Hz) for rigid rectangles lit from source s, heard at
/// listener l: Kirchhoff's integral p = (j k / 2 pi) sum over the rectangles of
/// e^{-jk(r1 + r2)} / (r1 r2) (cos1 + cos2) / 2 dA (midpoint rule, nu x nv cells each, fine
/// against the phase), p_image = e^{-jk R} / R with R the image source's distance (the
/// rectangles in one plane).
inline double kirchhoff(const std::vector<Rect>& rects, const glm::dvec3& s, const glm::dvec3& l,
                        double f, int nu, int nv) {
  const double k = 2.0 * std::numbers::pi * f / kKirchhoffC;
  const glm::dvec3 n = glm::normalize(glm::cross(rects[0].u, rects[0].v));
  std::complex<double> sum(0.0, 0.0);
  for (const Rect& r : rects) {
    const double cell = glm::length(r.u) * glm::length(r.v) / (double(nu) * nv);
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const glm::dvec3 x = r.o + (i + 0.5) / nu * r.u + (j + 0.5) / nv * r.v;
        const double r1 = glm::distance(x, s), r2 = glm::distance(x, l);
        const double obliquity =
            0.5 * (std::abs(glm::dot(s - x, n)) / r1 + std::abs(glm::dot(l - x, n)) / r2);
        sum += std::polar(cell * obliquity / (r1 * r2), -k * (r1 + r2));
      }
  }
  const std::complex<double> p = std::complex<double>(0.0, k / (2.0 * std::numbers::pi)) * sum;
  const glm::dvec3 image = s - 2.0 * glm::dot(s - rects[0].o, n) * n;
  const double big = glm::distance(image, l);
  return std::norm(p / std::polar(1.0 / big, -k * big));
}

/// The octave's mean of kirchhoff over 16 log-spaced frequencies, dB.
inline double kirchhoffBandDb(const std::vector<Rect>& rects, const glm::dvec3& s,
                              const glm::dvec3& l, int band, int nu, int nv) {
  double sum = 0.0;
  for (int i = 0; i < 16; ++i)
    sum +=
        kirchhoff(rects, s, l, bandCentreExactHz(band) * std::exp2((i + 0.5) / 16 - 0.5), nu, nv);
  return 10.0 * std::log10(sum / 16.0);
}

}  // namespace dpc::test
