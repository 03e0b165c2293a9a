// The crossover that joins the wave band to the ray-traced IR (wave/wave_join.h,
// common/butterworth.h), measured by FFT of impulse responses (a direct DFT here, not the
// filters' own response formula), against the analytic Butterworth magnitude
// 1 / (1 + (W / Wc)^(2N)) at the prewarped frequency W = tan(pi f / fs).
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "common/butterworth.h"
#include "wave/wave_join.h"

namespace dpc {
namespace {

using K = Butterworth::Kind;
constexpr double kFs = 48000.0;
constexpr size_t kLength = 1 << 15;  // 0.68 s: a 100 Hz 3rd-order filter rings out to 1e-9

std::vector<float> impulse(const Butterworth& f) {
  std::vector<float> x(kLength, 0.f);
  x[0] = 1.f;
  f.run(x);
  return x;
}

std::complex<double> dft(const std::vector<float>& x, double hz) {
  std::complex<double> sum = 0.0;
  const std::complex<double> w = std::polar(1.0, -2.0 * std::numbers::pi * hz / kFs);
  std::complex<double> z = 1.0;
  for (float v : x) sum += double(v) * z, z *= w;
  return sum;
}

double analyticPower(K kind, int order, double fc, double hz) {
  const double r = std::tan(std::numbers::pi * hz / kFs) / std::tan(std::numbers::pi * fc / kFs);
  const double p = std::pow(r, 2 * order);
  return kind == K::kLowPass ? 1.0 / (1.0 + p) : p / (1.0 + p);
}

}  // namespace

TEST_CASE("Butterworth: magnitude as the analog prototype's at prewarped frequencies",
          "[wave][crossover]") {
  for (int order : {2, 3, 4})
    for (K kind : {K::kLowPass, K::kHighPass}) {
      const auto x = impulse(Butterworth::design(kind, order, 250.0, kFs));
      for (double hz : {31.25, 125.0, 250.0, 500.0, 2000.0}) {
        INFO("order " << order << " at " << hz << " Hz");
        // float samples: the measured power is good to about 1e-6 of the passband.
        CHECK(std::abs(std::norm(dft(x, hz)) - analyticPower(kind, order, 250.0, hz)) < 1e-5);
      }
    }
}

TEST_CASE("Crossover: power complementary, and its sum an allpass (odd order)",
          "[wave][crossover]") {
  const double fc = 200.0;
  const auto lp = impulse(Butterworth::design(K::kLowPass, wave::kCrossoverOrder, fc, kFs));
  const auto hp = impulse(Butterworth::design(K::kHighPass, wave::kCrossoverOrder, fc, kFs));
  for (double hz : {25.0, 100.0, 170.0, 200.0, 235.0, 400.0, 1600.0}) {
    const auto a = dft(lp, hz), b = dft(hp, hz);
    INFO(hz << " Hz");
    CHECK(std::abs(std::norm(a) + std::norm(b) - 1.0) < 1e-5);  // incoherent bands: level kept
    CHECK(std::abs(std::norm(a + b) - 1.0) < 1e-5);              // the same signal in both
  }
}

TEST_CASE("Allpass: unit magnitude, twice the low-pass's phase", "[wave][crossover]") {
  const auto ap = impulse(Butterworth::design(K::kAllPass, 4, 500.0, kFs));
  const auto lp = impulse(Butterworth::design(K::kLowPass, 4, 500.0, kFs));
  for (double hz : {50.0, 250.0, 500.0, 1000.0}) {
    INFO(hz << " Hz");
    const auto a = dft(ap, hz), l = dft(lp, hz);
    CHECK(std::abs(std::abs(a) - 1.0) < 1e-5);
    CHECK(std::abs(std::arg(a / (l * l))) < 1e-4);  // arg a = 2 arg l (mod 2 pi)
  }
}

TEST_CASE("joinWaveBand: the same field in both bands keeps its level across the crossover",
          "[wave][crossover]") {
  // A direct sound as both bands hold it: a Dirac in the ray band; in the wave band the pulse
  // P (the low-pass at the maximum frequency) as each octave's simulation gives it, split at
  // the band edges and summed as wave/wave_band.cpp does.
  const double fc = 250.0, fmax = 500.0;
  std::vector<float> ray(kLength, 0.f), wave(kLength, 0.f), pulse(kLength, 0.f);
  ray[0] = 1.f;
  pulse[0] = 1.f;
  Butterworth::design(K::kLowPass, wave::kPulseOrder, fmax, kFs).run(pulse);
  const auto bands = wave::simulatedBands(fc);
  const auto edges = wave::bandEdges(bands);
  REQUIRE(bands.size() == 3);  // 63, 125, 250 Hz
  for (size_t k = 0; k < bands.size(); ++k) {
    std::vector<float> part = pulse;
    wave::splitBand(part, k, edges, kFs);
    for (size_t i = 0; i < kLength; ++i) wave[i] += part[i];
  }
  wave::joinWaveBand(ray, wave, 1.0, fc, fmax, kFs);
  for (double hz : {62.5, 125.0, 177.0, 250.0, 354.0}) {
    INFO(hz << " Hz");
    // |HP + LP |P|^2| with the phases matched; HP and LP in quadrature, so its square is
    // |HP|^2 + |P|^4 |LP|^2: 1 but for |P|^2 < 1 (0.996 at fmax / 2).
    const double lp2 = analyticPower(K::kLowPass, wave::kCrossoverOrder, fc, hz);
    const double p2 = analyticPower(K::kLowPass, wave::kPulseOrder, fmax, hz);
    const double expected = std::sqrt(1.0 - lp2 + p2 * p2 * lp2);
    CHECK(std::abs(std::abs(dft(ray, hz)) - expected) < 0.01);  // 0.09 dB
  }
}

TEST_CASE("Band split: the bands of one signal sum to an allpass, each its own octave",
          "[wave][crossover]") {
  const std::vector<double> edges = wave::bandEdges(wave::simulatedBands(250.0));
  REQUIRE(edges.size() == 2);  // 88 and 177 Hz
  std::vector<std::vector<float>> parts;
  std::vector<float> sum(kLength, 0.f);
  for (size_t k = 0; k < 3; ++k) {
    std::vector<float> x(kLength, 0.f);
    x[0] = 1.f;
    wave::splitBand(x, k, edges, kFs);
    for (size_t i = 0; i < kLength; ++i) sum[i] += x[i];
    parts.push_back(std::move(x));
  }
  for (double hz : {40.0, 88.0, 125.0, 177.0, 250.0, 1000.0}) {
    INFO(hz << " Hz");
    CHECK(std::abs(std::abs(dft(sum, hz)) - 1.0) < 1e-4);
  }
  // Each band dominates its own octave's centre: half an octave from an edge a 3rd-order
  // filter passes 8/9 and its complement 1/9 of the power (9 dB apart).
  const double centres[] = {62.5, 125.0, 250.0};
  for (size_t k = 0; k < 3; ++k)
    for (size_t j = 0; j < 3; ++j)
      if (j != k)
        CHECK(std::norm(dft(parts[k], centres[k])) > 7.0 * std::norm(dft(parts[j], centres[k])));
}

TEST_CASE("joinWaveBand: below the crossover the wave band, above it the ray band",
          "[wave][crossover]") {
  const double fc = 250.0;
  std::vector<float> ray(kLength, 0.f), wave(kLength, 0.f);
  ray[100] = 1.f;   // a ray-traced Dirac at 100 samples
  wave[300] = 2.f;  // a wave-band Dirac of twice its amplitude, later
  wave::joinWaveBand(ray, wave, 1.0, fc, 2 * fc, kFs);
  const auto spectrumAt = [&](double hz) { return std::abs(dft(ray, hz)); };
  CHECK(std::abs(spectrumAt(4000.0) - 1.0) < 1e-3);  // |HP3(16 fc)| = 1 - 1e-7
  CHECK(std::abs(spectrumAt(15.0) - 2.0) < 1e-3);    // |LP3(fc / 16) P(fc / 32)|: the wave band
  for (size_t i = 0; i < 100; ++i) CHECK(ray[i] == 0.f);  // causal: nothing before the Dirac
}

}  // namespace dpc
