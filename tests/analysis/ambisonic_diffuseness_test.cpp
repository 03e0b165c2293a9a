// Late-part diffuseness of AmbiX IRs against fields whose answer is known without dpc:
// one plane wave (every channel a fixed multiple of one noise: DirAC 0, COMEDIE 0), a diffuse
// field (independent noises with a diffuse field's SN3D channel powers 1 / (2n + 1): both 1
// up to the sampling error of the covariance), and K < (N + 1)^2 independent directions
// (COMEDIE at most 1 - (M - K) / (M - 1), its value when the K eigenvalues are equal).
// Tolerances: the covariance of M channels estimated from n independent samples has its
// eigenvalues within lambda (1 +- sqrt(M / n))^2 (Marchenko-Pastur), so a diffuse field reads
// COMEDIE >= 1 - 2 sqrt(M / n) M / (2 (M - 1)) and DirAC >= 1 - 3 / sqrt(n) (|sum W v| of
// independent noises is about sqrt(3 n) times their deviation); n = 2 B T in a band of B Hz.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "analysis/ambisonic_diffuseness.h"

using namespace dpc;
using audio::AmbisonicDiffuseness;

namespace {

constexpr int kRate = 48000;
constexpr size_t kLength = kRate;  // 1 s: 0.1 s of silence, then the field
constexpr size_t kStart = kRate / 10;

AmbisonicDiffuseness analyze(const std::vector<std::vector<float>>& channels, int order) {
  std::vector<const float*> p;
  for (const auto& c : channels) p.push_back(c.data());
  return audio::analyzeAmbisonicDiffuseness(p, order, kLength, kRate);
}

/// (order + 1)^2 channels of `sources` independent noises, source k with SN3D-like gains
/// gains(k, c); every channel silent before kStart.
template <class Gains>
std::vector<std::vector<float>> field(int order, int sources, Gains gains, uint32_t seed) {
  const size_t m = size_t((order + 1) * (order + 1));
  std::vector<std::vector<float>> ch(m, std::vector<float>(kLength, 0.f));
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.f, 0.1f);
  for (size_t t = kStart; t < kLength; ++t)
    for (int k = 0; k < sources; ++k) {
      const float s = g(rng);
      for (size_t c = 0; c < m; ++c) ch[c][t] += float(gains(k, int(c))) * s;
    }
  return ch;
}

/// Samples of the late part (80 ms after the onset on) of a band B Hz wide: 2 B T.
double lateSamples(double bandwidthHz) {
  return 2.0 * bandwidthHz * (double(kLength - kStart) / kRate - audio::kDiffusenessLateSeconds);
}

}  // namespace

TEST_CASE("Diffuseness: one plane wave reads 0 by both measures", "[analysis][ambisonics]") {
  // A direction's first-order gains (W = 1, Y, Z, X = the unit vector) and any gains above.
  const double x = 0.6, y = 0.0, z = 0.8;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> higher(16);
  for (double& h : higher) h = u(rng);
  const auto gains = [&](int, int c) {
    const double first[4] = {1.0, y, z, x};
    return c < 4 ? first[c] : higher[size_t(c)];
  };
  const AmbisonicDiffuseness a = analyze(field(3, 1, gains, 1), 3);
  CHECK(a.broadbandDirac < 1e-3);
  CHECK(a.broadbandComedie < 1e-3);
  for (int b = 2; b < kNumBands; ++b) {
    INFO("band " << b);
    CHECK(a.dirac[size_t(b)] < 1e-3);
    CHECK(a.comedie[size_t(b)] < 1e-3);
  }
}

TEST_CASE("Diffuseness: independent channels at a diffuse field's powers read 1",
          "[analysis][ambisonics]") {
  for (int order : {1, 3}) {
    const int m = (order + 1) * (order + 1);
    // Channel c as its own source, of SN3D power 1 / (2n + 1).
    const auto gains = [](int k, int c) {
      const double n = std::floor(std::sqrt(double(c)));
      return k == c ? 1.0 / std::sqrt(2.0 * n + 1.0) : 0.0;
    };
    const AmbisonicDiffuseness a = analyze(field(order, m, gains, 2 + uint32_t(order)), order);
    const auto comedieBound = [&](double n) {
      return 1.0 - 2.0 * std::sqrt(m / n) * m / (2.0 * (m - 1));
    };
    INFO("order " << order);
    CHECK(a.broadbandDirac >= 1.0 - 3.0 / std::sqrt(lateSamples(kRate / 2.0)));
    CHECK(a.broadbandComedie >= comedieBound(lateSamples(kRate / 2.0)));
    for (int b = 4; b < kNumBands; ++b) {  // 1 kHz up: enough samples per band for the bound
      const double bandwidth = bandCentreExactHz(b) / std::sqrt(2.0);
      INFO("band " << b << ": DirAC " << a.dirac[size_t(b)] << ", COMEDIE " << a.comedie[size_t(b)]);
      CHECK(a.dirac[size_t(b)] >= 1.0 - 3.0 / std::sqrt(lateSamples(bandwidth)));
      CHECK(a.comedie[size_t(b)] >= comedieBound(lateSamples(bandwidth)));
    }
  }
}

TEST_CASE("Diffuseness: fewer directions than channels lower COMEDIE, not DirAC",
          "[analysis][ambisonics]") {
  // Order 3 (M = 16) from K = 4 independent noises, each with random gains on every channel:
  // the covariance has rank 4, COMEDIE <= 1 - 12 / 15 = 0.2. DirAC sees only first order,
  // where 4 random sources already fill the 4 channels.
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<std::vector<double>> gain(4, std::vector<double>(16));
  for (auto& row : gain)
    for (double& v : row) v = g(rng);
  const auto gains = [&](int k, int c) { return gain[size_t(k)][size_t(c)]; };
  const AmbisonicDiffuseness a = analyze(field(3, 4, gains, 5), 3);
  const double bound = 1.0 - 12.0 / 15.0;
  CHECK(a.broadbandComedie <= bound + 0.02);  // 0.02: the sampling spread of the 4 eigenvalues
  for (int b = 4; b < kNumBands; ++b) {
    INFO("band " << b);
    CHECK(a.comedie[size_t(b)] <= bound + 0.02);
  }
}

TEST_CASE("Diffuseness: a silent IR or a wrong channel count gives NaN", "[analysis][ambisonics]") {
  std::vector<std::vector<float>> silent(4, std::vector<float>(kLength, 0.f));
  CHECK(std::isnan(analyze(silent, 1).broadbandComedie));
  CHECK(std::isnan(analyze(silent, 1).onsetSeconds));
  CHECK(std::isnan(analyze(silent, 2).broadbandDirac));  // 4 channels are not order 2's 9
}
