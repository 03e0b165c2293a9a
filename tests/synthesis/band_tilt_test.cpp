// The within-band tilt's windows read from suffix sums (TiltWindowSums) against the direct sum
// over each window (halfBandDensity), the definition both synthesisers and the exact-IR model
// share.
#include "synthesis/band_tilt.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <utility>

#include "engine/energy_response.h"

using namespace dpc;

namespace {

/// A response as the estimator gives one: nothing before the direct sound, then an
/// exponential decay per band (8 kHz fastest) with Monte Carlo scatter and empty bins, a second
/// room's later build-up, and a negative bin (a subtractive estimate) that counts as 0.
EnergyResponse realisticResponse(double binSeconds, size_t bins, unsigned seed) {
  EnergyResponse er(double(bins) * binSeconds, binSeconds);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (size_t k = 0; k < er.binCount(); ++k) {
    const double t = double(k) * binSeconds;
    if (t < 0.012) continue;
    for (int b = 0; b < kNumBands; ++b) {
      const double decay = std::exp(-13.8 * t / (1.6 - 0.15 * b));
      const double coupled = t > 0.3 ? 1e-3 * std::exp(-13.8 * (t - 0.3) / 3.0) : 0.0;
      const float scatter = u(rng) < 0.2f ? 0.f : 2.f * u(rng);
      er.bins()[k][b] = float((decay + coupled) * scatter * std::pow(0.5, b));
    }
  }
  er.bins()[40][3] = -1e-4f;
  return er;
}

}  // namespace

TEST_CASE("Tilt windows from suffix sums equal the direct window sums", "[synthesis][tilt]") {
  // The two differ only by rounding: the suffix difference loses the bits the later tail holds
  // beyond the window (here at most e^(13.8 x 3 s / 3 s) ~ 1e6 of it in the slow coupled tail),
  // so 1e-9 relative holds with margin for double sums (1e-16 x 1e6 = 1e-10).
  for (const double binSeconds : {1e-3, 2.5e-3}) {
    const EnergyResponse er = realisticResponse(binSeconds, size_t(2.0 / binSeconds), 7);
    TiltWindowSums sums;
    sums.reset(er);
    size_t compared = 0;
    for (int b = 0; b < kNumBands; ++b)
      for (double t = 0.0; t < 2.05; t += 0.37e-3) {  // past the end too: empty windows
        const HalfBandDensity direct = halfBandDensity(er, b, t);
        const HalfBandDensity fast = sums.at(b, t);
        INFO("bin " << binSeconds << " s, band " << b << ", t " << t << " s");
        REQUIRE(fast.low == Approx(direct.low).epsilon(1e-9));
        REQUIRE(fast.high == Approx(direct.high).epsilon(1e-9));
        compared += direct.low != 1.0 || direct.high != 1.0;
      }
    CHECK(compared > 10000);  // the tilt is not trivially 1 where the sums are compared
  }
}

TEST_CASE("Tilt windows follow a new response after reset", "[synthesis][tilt]") {
  const EnergyResponse a = realisticResponse(1e-3, 500, 1), b = realisticResponse(1e-3, 300, 2);
  TiltWindowSums sums;
  sums.reset(a);
  const HalfBandDensity fromA = sums.at(4, 0.1);
  sums.reset(b);  // a shorter response: the suffix sums end where it ends
  const HalfBandDensity fromB = sums.at(4, 0.1), direct = halfBandDensity(b, 4, 0.1);
  CHECK(fromB.high == Approx(direct.high).epsilon(1e-9));
  CHECK(fromB.high != fromA.high);      // the same window, not the previous response's result
  CHECK(sums.at(4, 0.45).high == 1.0);  // beyond b's end: no energy, no tilt
}

TEST_CASE("The tilt is the log-linear density's mean over each half band", "[synthesis][tilt]") {
  // Oracle: the mean over x in [0, 1/2] of ratio^x by the midpoint rule (10^5 points: error
  // below 1e-9 relative for these ratios), against halfBandDensity on a response whose
  // neighbouring bands hold the given ratios throughout the window.
  auto mean = [](double ratio) {
    const int n = 100000;
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += std::pow(ratio, 0.5 * (i + 0.5) / n);
    return s / n;
  };
  for (const auto& [below, above] : {std::pair{4.0, 0.125}, std::pair{1.0, 1.0},
                                     std::pair{1.000001, 0.999}, std::pair{1e-3, 50.0}}) {
    EnergyResponse er(0.1, 1e-3);
    for (size_t k = 0; k < er.binCount(); ++k) {
      er.bins()[k][3] = 1e-4f;
      er.bins()[k][2] = float(1e-4 * below);
      er.bins()[k][4] = float(1e-4 * above);
    }
    const HalfBandDensity d = halfBandDensity(er, 3, 0.05);
    INFO("ratios " << below << ", " << above);
    // The energies are floats: the ratio itself is exact only to 1e-7.
    CHECK(d.low == Approx(mean(double(er.bins()[0][2]) / double(er.bins()[0][3]))).epsilon(1e-7));
    CHECK(d.high == Approx(mean(double(er.bins()[0][4]) / double(er.bins()[0][3]))).epsilon(1e-7));
  }
  // Beyond kTiltMaxLog the ratio is held at e^(+-kTiltMaxLog).
  EnergyResponse steep(0.1, 1e-3);
  for (size_t k = 0; k < steep.binCount(); ++k) {
    steep.bins()[k][3] = 1.f;
    steep.bins()[k][4] = 1e-12f;
  }
  CHECK(halfBandDensity(steep, 3, 0.05).high == Approx(mean(std::exp(-kTiltMaxLog))).epsilon(1e-7));
}
