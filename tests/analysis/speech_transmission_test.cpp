// Tests for analysis/speech_transmission against IEC 60268-16:2020's closed forms: an ideal
// impulse (m = 1 at every F) gives STI 1; an exponential energy decay of reverberation time T
// has m(F) = 1 / sqrt(1 + (2 pi F T / 13.8)^2) (Schroeder 1981; IEC 60268-16 Annex A), so
// its STI is the weighting of that m.
#include "analysis/speech_transmission.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <vector>

using namespace dpc::audio;

namespace {

constexpr double kBin = 1e-4;  ///< 0.1 ms bins: the bin-centre sampling error is < 1e-4 in m

/// exp(-13.8 t / T) in bins of kBin over 8 T (the tail beyond is below -110 dB).
std::vector<double> exponentialDecay(double t60) {
  std::vector<double> e(size_t(8.0 * t60 / kBin));
  for (size_t i = 0; i < e.size(); ++i) e[i] = std::exp(-13.8 * (double(i) + 0.5) * kBin / t60);
  return e;
}

/// The standard's STI of a noise-free exponential decay of T60 (same in every band).
double formulaSti(double t60) {
  double mti = 0.0;
  for (const double f : kStiModulationHz) {
    const double x = 2.0 * std::numbers::pi * f * t60 / 13.8;
    const double m = 1.0 / std::sqrt(1.0 + x * x);
    const double snr = std::clamp(10.0 * std::log10(m / (1.0 - m)), -15.0, 15.0);
    mti += (snr + 15.0) / 30.0 / kStiModulationFrequencies;
  }
  std::array<double, kStiBands> bands;
  bands.fill(mti);
  return stiFromMti(bands);
}

double stiOf(const std::vector<double>& e) {
  std::array<std::span<const double>, kStiBands> bands;
  bands.fill(std::span<const double>(e));
  return speechTransmissionIndex(bands, kBin);
}

}  // namespace

TEST_CASE("STI: an ideal impulse gives 1", "[analysis][sti]") {
  const std::vector<double> impulse = {1.0, 0.0, 0.0, 0.0};
  CHECK(stiOf(impulse) == Approx(1.0).margin(1e-12));
}

TEST_CASE("STI: the weights of a perfect channel sum to 1", "[analysis][sti]") {
  std::array<double, kStiBands> ones;
  ones.fill(1.0);
  CHECK(stiFromMti(ones) == Approx(1.0).margin(1e-12));
  ones.fill(0.0);
  CHECK(stiFromMti(ones) == Approx(0.0).margin(1e-12));
}

TEST_CASE("STI: exponential decays give the standard's formula within 0.01", "[analysis][sti]") {
  for (const double t60 : {0.3, 0.6, 1.0, 2.0, 4.0}) {
    INFO("T60 = " << t60 << " s");
    const double expected = formulaSti(t60);
    CHECK(stiOf(exponentialDecay(t60)) == Approx(expected).margin(0.01));
  }
  // Longer reverberation is less intelligible, and the formula's values fall in the ranges
  // the standard's Annex G tabulates (about 0.8 at 0.3 s .. 0.35 at 4 s).
  CHECK(formulaSti(0.3) > formulaSti(1.0));
  CHECK(formulaSti(1.0) > formulaSti(4.0));
}

TEST_CASE("STI: a silent band gives NaN", "[analysis][sti]") {
  const std::vector<double> silent(10, 0.0);
  CHECK(std::isnan(stiOf(silent)));
  CHECK(std::isnan(modulationTransfer(silent, kBin, 1.0)));
}
