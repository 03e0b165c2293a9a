// IACC (ISO 3382-1 Annex B) against ear signals whose correlation is known by construction:
// one Gaussian noise heard by both ears (delayed, inverted), independent noises, and their
// mixture sqrt(a) common + sqrt(1 - a) own, whose interaural coherence is a. Tolerances come
// from the noise: a correlation estimated over B T independent samples (B the bandwidth in
// Hz, T the window in s; 2 fs T broadband) scatters by about 1 / sqrt(B T), and the maximum
// over the lags adds up to about that again.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "analysis/interaural_correlation.h"

using namespace dpc;
using dpc::audio::analyzeBinaural;

namespace {

constexpr int kRate = 48000;

std::vector<float> noise(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  std::vector<float> x(n);
  for (float& v : x) v = g(rng);
  return x;
}

/// x delayed by `samples` (>= 0) and scaled.
std::vector<float> delayed(const std::vector<float>& x, size_t samples, float scale = 1.f) {
  std::vector<float> y(x.size(), 0.f);
  for (size_t i = samples; i < x.size(); ++i) y[i] = scale * x[i - samples];
  return y;
}

/// Expected scatter of a correlation over a window of T seconds in octave band b (or
/// broadband when b < 0): 1 / sqrt(B T), B the band's width (fc / sqrt 2) or fs / 2.
double scatter(int b, double seconds) {
  const double width = b < 0 ? kRate / 2.0 : bandCentreExactHz(b) / std::sqrt(2.0);
  return 1.0 / std::sqrt(width * seconds);
}

}  // namespace

TEST_CASE("IACC: one sound at both ears, delayed up to 1 ms or inverted, reads 1") {
  const std::vector<float> left = noise(kRate, 1);
  for (const float scale : {1.f, -0.5f}) {
    const auto right = delayed(left, 36, scale);  // 0.75 ms
    const auto a = analyzeBinaural(left.data(), right.data(), left.size(), kRate);
    // The delay moves 36 of the early window's 3840 samples out of it: 1 - 36/3840 at worst.
    CHECK(a.broadband.early > 0.99);
    CHECK(a.broadband.late > 0.99);
    for (int b = 2; b < kNumBands; ++b) {
      INFO("band " << b);
      CHECK(a.bands[size_t(b)].late > 0.98);
    }
  }
}

TEST_CASE("IACC: a delay beyond 1 ms, or independent ears, reads the noise floor") {
  const std::vector<float> left = noise(kRate, 2);
  const std::vector<std::vector<float>> rights = {delayed(left, 240), noise(kRate, 3)};  // 5 ms
  for (const auto& right : rights) {
    const auto a = analyzeBinaural(left.data(), right.data(), left.size(), kRate);
    const double late = 1.0 - audio::kInterauralEarlySeconds;
    CHECK(a.broadband.late < 4.0 * scatter(-1, late));
    for (int b = 3; b < kNumBands; ++b) {
      INFO("band " << b << ": IACC_L " << a.bands[size_t(b)].late);
      CHECK(a.bands[size_t(b)].late < 4.0 * scatter(b, late));
    }
  }
}

TEST_CASE("IACC: ears sharing a fraction a of their energy read a") {
  const size_t n = 2 * kRate;
  const std::vector<float> common = noise(n, 4), ownL = noise(n, 5), ownR = noise(n, 6);
  const auto commonR = delayed(common, 20);  // 0.42 ms, as from a source off to one side
  for (const double share : {0.3, 0.7}) {
    std::vector<float> left(n), right(n);
    for (size_t i = 0; i < n; ++i) {
      left[i] = float(std::sqrt(share) * common[i] + std::sqrt(1 - share) * ownL[i]);
      right[i] = float(std::sqrt(share) * commonR[i] + std::sqrt(1 - share) * ownR[i]);
    }
    const auto a = analyzeBinaural(left.data(), right.data(), n, kRate);
    const double late = 2.0 - audio::kInterauralEarlySeconds;
    CHECK(std::abs(a.broadband.late - share) < 4.0 * scatter(-1, late) + 0.01);
    for (int b = 3; b < kNumBands; ++b) {  // 500 Hz and up: B T > 600
      INFO("share " << share << ", band " << b << ": IACC_L " << a.bands[size_t(b)].late);
      CHECK(std::abs(a.bands[size_t(b)].late - share) < 4.0 * scatter(b, late));
    }
  }
}

TEST_CASE("IACC: the early and the late window are read apart at 80 ms") {
  // Both ears hear one sound for the first 80 ms after the direct sound, then their own.
  const size_t n = kRate, split = size_t(audio::kInterauralEarlySeconds * kRate);
  std::vector<float> left = noise(n, 7), right = noise(n, 8);
  left[0] = right[0] = 40.f;  // the direct sound: t0 at sample 0 in both ears
  for (size_t i = 1; i < split; ++i) right[i] = left[i];
  const auto a = analyzeBinaural(left.data(), right.data(), n, kRate);
  CHECK(a.onsetSeconds == 0.0);
  CHECK(a.broadband.early > 0.99);
  CHECK(a.broadband.late < 4.0 * scatter(-1, 1.0 - audio::kInterauralEarlySeconds));
  // The whole IR: the early part's energy share (8 % of the noise plus the Dirac) correlates.
  CHECK(a.broadband.all > a.broadband.late);
  CHECK(a.broadband.all < a.broadband.early);
}

TEST_CASE("IACC: a silent ear gives NaN, not a number") {
  const std::vector<float> left = noise(4800, 9), right(4800, 0.f);
  const auto a = analyzeBinaural(left.data(), right.data(), left.size(), kRate);
  CHECK(std::isnan(a.broadband.late));
  CHECK(std::isnan(a.bands[4].early));
  const auto none = analyzeBinaural(right.data(), right.data(), right.size(), kRate);
  CHECK(std::isnan(none.onsetSeconds));
}
