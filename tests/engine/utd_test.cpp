// The UTD coefficient by its terms' asymptotic order sums (engine/utd.h utdTermSums) against
// the term-by-term sum of four transition functions: the same series, regrouped, so the two
// agree to rounding wherever every term is past the series' switch, and the sums fall back to
// the terms below it. And the band's coefficients interpolated between its anchor frequencies
// (engine/diffraction.h interpolatedUtd) against the coefficient at every frequency.
#include "engine/utd.h"

#include "engine/diffraction.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

using namespace dpc;

TEST_CASE("UTD: the order sums equal the four terms' series, and fall back below the switch",
          "[diffraction]") {
  constexpr double kPi = std::numbers::pi;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int summed = 0, fellBack = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    // A wedge of air angle n pi, n in (1.05, 2), source and receiver anywhere inside it.
    const double n = 1.05 + 0.95 * unit(rng);
    const double phiS = 1e-3 + (n * kPi - 2e-3) * unit(rng);
    const double phi = 1e-3 + (n * kPi - 2e-3) * unit(rng);
    const auto terms = utdWedgeTerms(n, phi, phiS);
    const UtdTermSums sums = utdTermSums(terms);
    const double prefactor = utdPrefactor(n, 0.2 + 0.8 * unit(rng));
    const double kl = std::pow(10.0, -1.0 + 5.0 * unit(rng));  // 0.1 .. 1e4
    const std::complex<double> byTerms = utdScaled(terms, prefactor, kl);
    const std::complex<double> bySums = utdScaled(terms, sums, prefactor, kl);
    // Rounding: each term's cot times |F| <= 1, the series' terms at most 1 at X >= 12.
    double scale = 0.0;
    for (const UtdTerm& t : terms) scale += std::abs(t.cot);
    scale *= prefactor;
    INFO("n " << n << " phi " << phi << " phiS " << phiS << " kl " << kl);
    CHECK(std::abs(bySums - byTerms) <= 1e-12 * scale + 1e-15);
    (kl * sums.aMin >= 12.0 ? summed : fellBack) += 1;
  }
  // Both regimes were exercised.
  CHECK(summed > 200);
  CHECK(fellBack > 200);
}

TEST_CASE("UTD: a path's phasor within 5e-7 of e^{-j kl} up to kl = 1e5", "[diffraction]") {
  // Single-precision sine and cosine of the phase reduced in double precision: the error is
  // float's rounding of a value in [-pi, pi] (2^-24 pi = 1.9e-7) plus sinf's half ulp.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> exponent(-3.0, 5.0);
  double worst = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const double kl = std::pow(10.0, exponent(rng)) * (i % 2 ? 1.0 : -1.0);
    worst = std::max(worst, std::abs(pathPhasor(kl) - std::polar(1.0, -kl)));
  }
  INFO("largest error " << worst);
  CHECK(worst < 5e-7);
  CHECK(worst > 0.0);  // single precision: not the double-precision phasor by accident
}

TEST_CASE("UTD: coefficients interpolated across a band keep its level within 0.05 dB",
          "[diffraction]") {
  // Band means of |D|^2 / k (a path's level alone) and of |direct + path|^2 (the coherent sum
  // where the two are equal, as on the shadow boundary: the sum's deepest notches), from D at
  // the band's anchors and interpolated (as EdgeDiffraction::apply does) against D at all of
  // its frequencies. Bound: 0.05 dB, the residual of UTD itself against the exact
  // Biot-Tolstoy-Medwin wedge at 250 Hz (diffraction_test): the interpolation adds less than
  // the method's own error. Wedges n in (1.05, 2), any angles, L from 5 cm to 50 m, 63 Hz-8 kHz.
  constexpr double kPi = std::numbers::pi, kC = 343.0;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worstAlone = 0.0, worstSum = 0.0;
  for (int trial = 0; trial < 3000; ++trial) {
    const double n = 1.05 + 0.95 * unit(rng);
    const double phiS = 1e-3 + (n * kPi - 2e-3) * unit(rng);
    const double phi = 1e-3 + (n * kPi - 2e-3) * unit(rng);
    const auto terms = utdWedgeTerms(n, phi, phiS);
    const UtdTermSums sums = utdTermSums(terms);
    const double prefactor = utdPrefactor(n, 0.3 + 0.7 * unit(rng));
    const double L = 0.05 * std::pow(1000.0, unit(rng));
    const double extra = 3.0 * unit(rng);  // the path's length beyond the direct one, m
    const int b = trial % kNumBands;
    const auto k = [&](int i) { return 2 * kPi * diffractionFrequencyHz(b, i) / kC; };
    std::array<std::complex<double>, kUtdAnchorsPerBand> anchors;
    for (int a = 0; a < kUtdAnchorsPerBand; ++a)
      anchors[size_t(a)] = utdScaled(terms, sums, prefactor, k(utdAnchorIndex(a)) * L);
    double exactAlone = 0.0, interpAlone = 0.0, meanAmplitude = 0.0;
    std::array<std::complex<double>, kDiffractionFrequenciesPerBand> exact{}, interp{};
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      exact[size_t(i)] = utdScaled(terms, sums, prefactor, k(i) * L) / std::sqrt(k(i));
      interp[size_t(i)] = interpolatedUtd(anchors, i) / std::sqrt(k(i));
      exactAlone += std::norm(exact[size_t(i)]);
      interpAlone += std::norm(interp[size_t(i)]);
      meanAmplitude += std::abs(exact[size_t(i)]) / kDiffractionFrequenciesPerBand;
    }
    if (!(exactAlone > 0.0)) continue;
    double exactSum = 0.0, interpSum = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const std::complex<double> direct = meanAmplitude * std::polar(1.0, k(i) * extra);
      exactSum += std::norm(direct + exact[size_t(i)]);
      interpSum += std::norm(direct + interp[size_t(i)]);
    }
    const double alone = std::abs(10 * std::log10(interpAlone / exactAlone));
    const double sum = std::abs(10 * std::log10(interpSum / exactSum));
    INFO("n " << n << " phi " << phi << " phiS " << phiS << " L " << L << " band " << b);
    CHECK(alone < 0.05);
    CHECK(sum < 0.05);
    worstAlone = std::max(worstAlone, alone);
    worstSum = std::max(worstSum, sum);
  }
  std::printf("interpolated UTD: largest band error %.4f dB alone, %.4f dB summed\n",
              worstAlone, worstSum);
}
