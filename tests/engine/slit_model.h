// The slit model of engine/slit.h (Gomperts 1964; Mechel 1986) computed on its own for the
// door tests (door_gap_test, door_frame_test): the mouth impedance by quadrature of Bessel
// functions, each slit's line source by quadrature along it with the exact geometry, the
// parallel slits' mutual loading by Cramer's rule (dpc: a power series, the paraxial Fresnel
// integral and Eigen). Test helpers; allocates; no errors.
#pragma once

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <cstdio>
#include <glm/geometric.hpp>
#include <utility>
#include <vector>

#include "engine/diffraction.h"
#include "tests/engine/door_scenes.h"

namespace dpc::door_test {

using C = std::complex<double>;

/// The baffled strip's mouth impedance over omega rho per unit length, by quadrature of its
/// definition z_r(X) = (1 / X^2) int_0^X (X - t) (J0(t) - j Y0(t)) dt (t = X v^2 removes
/// Y0's logarithm at 0; 64 Gauss-Legendre panels in v), tabulated in log X.
class MouthImpedance {
 public:
  MouthImpedance() {
    for (int i = 0; i < kPoints; ++i) table_[size_t(i)] = direct(std::exp(kLogLo + i * kStep));
  }
  C operator()(double x) const {
    const double u = std::clamp((std::log(x) - kLogLo) / kStep, 0.0, double(kPoints - 1) - 1e-9);
    const size_t i = size_t(u);
    return table_[i] + (u - double(i)) * (table_[i + 1] - table_[i]);
  }

 private:
  static C direct(double x) {
    C sum = 0.0;
    constexpr int kPanels = 64;
    for (int p = 0; p < kPanels; ++p)
      for (size_t g = 0; g < kGlX.size(); ++g) {
        const double v = (p + 0.5 * (kGlX[g] + 1.0)) / kPanels, t = x * v * v;
        const C h(std::cyl_bessel_j(0.0, t), -std::cyl_neumann(0.0, t));
        sum += kGlW[g] * 0.5 / kPanels * (x - t) * h * 2.0 * x * v;
      }
    return sum / (x * x);
  }
  static constexpr int kPoints = 600;
  static constexpr double kLogLo = -11.0, kStep = (2.6 - kLogLo) / (kPoints - 1);  // X to 13.5
  std::array<C, kPoints> table_{};
};

/// One straight slit of the model: centre line from a to b, width w, depth d (0: in a sheet),
/// in a wall x = const.
struct Slit {
  glm::dvec3 a, b;
  double width;
  double depth = 0.0;
};

/// The slit's transfer t(X) (q = t p_i / (omega rho)) for X = k_t w and k_t d: a plane wave
/// through the depth, driven by the blocked pressure at one mouth and loaded by both mouths'
/// impedance (Mechel 1986; Vigran, Building Acoustics, eq. 9.4, for holes); 1 / z_r in a sheet.
inline C transfer(const MouthImpedance& zr, double x, double kd) {
  const C z = zr(x);
  return 2.0 / (2.0 * z * std::cos(kd) + C(0.0, 1.0) * (1.0 / x + z * z * x) * std::sin(kd));
}

/// The model's pressure at the listener re the free field's amplitude 1 / d: the sum over the
/// slits of int (j / 2 pi) t(X) D_S D_L e^{-jk(r + R)} / (r R) dz, t = 1 / z_r for a slit in a
/// sheet, X = k sin(beta) w, D = sinc(X sin(theta) / 2), by Gauss-Legendre panels of 1 cm.
/// Per slit, the factor its volume velocity takes from the others' radiation load: Z q = p
/// against q_i = p_i / Z_ii, Z_ii = z_r(k w), Z_ij = H0^(2)(k d) / 2 for parallel slits d apart
/// (all lie in the wall x = 6), p_i the incident field at the slit's point level with the
/// source; Cramer's rule on the parallel ones (at most three here), 1 for the others
/// (engine/slit.h's mutualLoading, computed here on its own).
inline std::vector<C> loadingFactors(const std::vector<Slit>& slits, double k, const MouthImpedance& zr,
                              const glm::dvec3& S) {
  std::vector<C> f(slits.size(), 1.0);
  std::vector<size_t> vertical;  // along y: parallel to each other (the top slit runs along z)
  for (size_t i = 0; i < slits.size(); ++i)
    if (slits[i].a.z == slits[i].b.z) vertical.push_back(i);
  if (vertical.size() < 2) return f;
  const size_t n = vertical.size();
  std::vector<std::vector<C>> z(n, std::vector<C>(n));
  std::vector<C> p(n);
  for (size_t i = 0; i < n; ++i) {
    const Slit& si = slits[vertical[i]];
    const glm::dvec3 P(si.a.x, std::clamp(S.y, si.a.y, si.b.y), si.a.z);
    p[i] = std::polar(1.0 / glm::length(P - S), -k * glm::length(P - S));
    for (size_t j = 0; j < n; ++j) {
      const double d = std::abs(si.a.z - slits[vertical[j]].a.z);
      z[i][j] = i == j ? zr(k * si.width)
                       : 0.5 * C(std::cyl_bessel_j(0.0, k * d), -std::cyl_neumann(0.0, k * d));
    }
  }
  auto det = [&](const std::vector<std::vector<C>>& m) {
    if (n == 2) return m[0][0] * m[1][1] - m[0][1] * m[1][0];
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  REQUIRE(n <= 3);
  const C whole = det(z);
  for (size_t i = 0; i < n; ++i) {
    std::vector<std::vector<C>> m = z;
    for (size_t r = 0; r < n; ++r) m[r][i] = p[r];
    f[vertical[i]] = det(m) / whole * z[i][i] / p[i];
  }
  return f;
}

inline C modelPressure(const std::vector<Slit>& slits, double k, const MouthImpedance& zr,
                const glm::dvec3& S, const glm::dvec3& L) {
  const std::vector<C> loading = loadingFactors(slits, k, zr, S);
  C p = 0.0;
  for (size_t i = 0; i < slits.size(); ++i) {
    const Slit& s = slits[i];
    C slit = 0.0;
    const glm::dvec3 e = glm::normalize(s.b - s.a);
    const double length = glm::length(s.b - s.a);
    const int panels = int(std::ceil(length / 0.01));
    auto sinFromAxis = [&](const glm::dvec3& v) {  // in the plane across the slit
      const glm::dvec3 across = v - glm::dot(v, e) * e;
      return std::abs(across.y * e.z - across.z * e.y) / glm::length(across);  // not along x
    };
    for (int n = 0; n < panels; ++n)
      for (size_t g = 0; g < kGlX.size(); ++g) {
        const double z = (n + 0.5 * (kGlX[g] + 1.0)) * length / panels;
        const glm::dvec3 P = s.a + z * e;
        const double r = glm::length(P - S), R = glm::length(L - P);
        const double sinBeta = glm::length(glm::cross((P - S) / r, e));
        const double x = k * sinBeta * s.width;
        auto sinc = [](double u) { return std::abs(u) < 1e-9 ? 1.0 : std::sin(u) / u; };
        const double directivity =
            sinc(0.5 * x * sinFromAxis(P - S)) * sinc(0.5 * x * sinFromAxis(L - P));
        slit += kGlW[g] * 0.5 * length / panels * C(0.0, 1.0) / (2 * kPi) *
                transfer(zr, x, k * sinBeta * s.depth) * directivity *
                std::polar(1.0 / (r * R), -k * (r + R));
      }
    p += loading[i] * slit;
  }
  return p * double(glm::length(L - S));
}

/// The slits centred in the gaps round a leaf `gap` metres from the frame (none for 0), in the
/// plane x, `depth` metres deep (the leaf's thickness).
inline std::vector<Slit> perimeterSlits(double gap, double x = 6.0, double depth = 0.0) {
  const double z0 = kDoorZ0, z1 = kDoorZ0 + kDoorWidth, h = kDoorHeight;
  if (!(gap > 0.0)) return {};
  return {{{x, 0, z0 + gap / 2}, {x, h, z0 + gap / 2}, gap, depth},
          {{x, 0, z1 - gap / 2}, {x, h, z1 - gap / 2}, gap, depth},
          {{x, h - gap / 2, z0}, {x, h - gap / 2, z1}, gap, depth}};
}

/// The model's band levels (dB re the free field) of `slits` from source S to listener L: |p|^2
/// averaged over the band's frequencies.
inline Bands modelLevels(const std::vector<Slit>& slits, const MouthImpedance& zr,
                  const glm::dvec3& S = glm::dvec3(kSource),
                  const glm::dvec3& L = glm::dvec3(kListener)) {
  Bands out;
  for (int b = 0; b < kNumBands; ++b) {
    double mean = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const double k = 2 * kPi * diffractionFrequencyHz(b, i) / kC;
      mean += std::norm(modelPressure(slits, k, zr, S, L)) / kDiffractionFrequenciesPerBand;
    }
    out[b] = float(10 * std::log10(mean));
  }
  return out;
}

/// Source-listener pairs beside the doorway, both past one jamb, at other heights (the
/// off-axis tests).
inline const std::array<std::pair<glm::vec3, glm::vec3>, 4> kOffAxisPairs = {{
    {{3.f, 1.2f, 4.2f}, {9.f, 1.5f, 4.6f}},
    {{3.f, 1.6f, 0.6f}, {9.f, 1.0f, 1.2f}},
    {{4.f, 1.2f, 4.5f}, {8.f, 1.2f, 4.5f}},
    {{3.f, 0.5f, 3.5f}, {10.f, 2.5f, 4.0f}}}};

/// Prints one closed case's levels and dpc - model per band (the lines plot_doorways.py reads)
/// and checks it below the open doorway and the free field and within the 3 dB of
/// the model.
inline void checkClosedAgainstModel(const char* label, const Bands& closed, const Bands& open,
                             const Bands& model) {
  std::printf("%s: dpc, dpc - model (dB)", label);
  for (int b = 0; b < kNumBands; ++b)
    std::printf(" %5.1f/%+4.1f", double(closed[b]), double(closed[b] - model[b]));
  std::printf("\n");
  for (int b = 0; b < kNumBands; ++b) {
    INFO(label << ", band " << b);
    CHECK(closed[b] <= open[b]);
    CHECK(closed[b] <= 1e-4f);
    CHECK(std::abs(closed[b] - model[b]) < 3.f);
  }
}

}  // namespace dpc::door_test
