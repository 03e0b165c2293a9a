// Slits loading each other (engine/slit.h, mutualLoading) against the closed form for two equal
// slits: with equal incident pressures Z q = p gives q = p / (z_r + z_m), so each slit's factor
// is z_r / (z_r + z_m), z_m = H0^(2)(k d) / 2 written out here with std::cyl_bessel_j and
// std::cyl_neumann; and the cases that are not coupled.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <vector>

#include "engine/slit.h"

using namespace dpc;
using C = std::complex<double>;

namespace {

/// Two slits along y in the plane x = 0, d metres apart along z, width w, at wavenumber k,
/// the same incident pressure.
std::vector<CoupledSlit> pair(double d, double w, double k) {
  const glm::dvec3 along{0, 1, 0}, normal{1, 0, 0};
  return {{glm::dvec3(0, 0, 0), along, normal, k * w, k, C(0.3, -0.2)},
          {glm::dvec3(0, 0.7, d), along, normal, k * w, k, C(0.3, -0.2)}};
}

C factorOf(const std::vector<CoupledSlit>& slits, size_t i) {
  std::vector<C> f(slits.size());
  mutualLoading(slits, f);
  return f[i];
}

}  // namespace

TEST_CASE("Slits: two equal parallel slits take z_r / (z_r + H0(k d) / 2)", "[slit]") {
  const double w = 0.01;
  for (double d : {0.05, 0.5, 1.0, 3.0})
    for (double f : {63.0, 125.0, 500.0}) {
      const double k = 2 * std::numbers::pi * f / 343.0;
      const C zr = stripRadiationImpedance(k * w);
      const C zm = 0.5 * C(std::cyl_bessel_j(0.0, k * d), -std::cyl_neumann(0.0, k * d));
      const C want = zr / (zr + zm), got = factorOf(pair(d, w, k), 0);
      INFO("d " << d << " m, " << f << " Hz: " << got << " against " << want);
      CHECK(std::abs(got - want) < 1e-9 * std::abs(want));
      CHECK(std::abs(factorOf(pair(d, w, k), 1) - want) < 1e-9 * std::abs(want));
    }
}

TEST_CASE("Slits: close slits pass less than alone, far ones as alone", "[slit]") {
  // Rayleigh's principle for the pair: 5 cm apart at 63 Hz (k d = 0.06) they share their
  // radiation resistance and each carries less; 100 m apart at 500 Hz (k d = 920) the mutual
  // term, |H0(k d)| / 2 = sqrt(2 / (pi k d)) / 2 = 0.013 against |z_r| of about 1.5, moves each
  // by about 1 %.
  const double w = 0.01;
  const double k63 = 2 * std::numbers::pi * 63.0 / 343.0, k500 = 2 * std::numbers::pi * 500.0 / 343.0;
  CHECK(std::abs(factorOf(pair(0.05, w, k63), 0)) < 0.9);
  CHECK(std::abs(factorOf(pair(100.0, w, k500), 0) - 1.0) < 0.02);
}

TEST_CASE("Slits: slits not parallel or not in one plane are not coupled", "[slit]") {
  const double k = 2 * std::numbers::pi * 63.0 / 343.0, w = 0.01;
  std::vector<CoupledSlit> s = pair(0.5, w, k);
  s[1].along = {0, 0, 1};  // a door's top gap against a side gap
  CHECK(factorOf(s, 0) == C(1.0, 0.0));
  s = pair(0.5, w, k);
  s[1].point.x = 0.3;  // the other face of a thick wall
  CHECK(factorOf(s, 0) == C(1.0, 0.0));
  s = pair(0.5, w, k);
  CHECK(factorOf(s, 0) != C(1.0, 0.0));  // the same pair in one plane is
}
