// The noise made orthogonal to an IR's deterministic part (synthesis/noise_orthogonaliser.h):
// afterwards the ISO 3382-1 octave analysis of noise + fixed reads the sum of the two's
// energies in every band the caller levels. The instrument is the analysis filter run causally
// in the time domain over the whole signal (OctaveBandPass::run, as analyzeImpulseResponse
// reads an IR), not the zero-phase power kernel on FFT bins that the orthogonaliser uses: the
// two agree only if the orthogonaliser's kernel, its padding and its support are right.
#include "synthesis/noise_orthogonaliser.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "common/octave_band_masks.h"
#include "common/octave_filter.h"

using namespace dpc;

namespace {

constexpr int kFs = 48000;
constexpr size_t kLength = kFs;  // 1 s IRs
constexpr int kFirst = 1, kLast = 5;  // 125 Hz - 2 kHz

/// Band b's reading of x (rung out for 0.5 s past its end): sum of the squared filter output.
std::vector<double> filtered(const std::vector<float>& x, int b) {
  std::vector<double> in(x.begin(), x.end()), out(x.size() + kFs / 2);
  in.resize(out.size(), 0.0);
  OctaveBandPass::State state{};
  OctaveBandPass::design(bandCentreExactHz(b), kFs).run(in.data(), out.data(), in.size(), state);
  return out;
}

/// The band-b cross term <H_b f, H_b n> over the band energy of f + n.
double relativeCross(const std::vector<float>& f, const std::vector<float>& n, int b) {
  const std::vector<double> yf = filtered(f, b), yn = filtered(n, b);
  double cross = 0.0, total = 0.0;
  for (size_t t = 0; t < yf.size(); ++t) {
    cross += yf[t] * yn[t];
    total += (yf[t] + yn[t]) * (yf[t] + yn[t]);
  }
  return cross / total;
}

/// A room-like pair: a direct pulse at 20 ms and two reflections (the fixed part), and a
/// decaying Gaussian noise from 22 ms on with a cleared gap around the second reflection.
struct Pair {
  std::vector<float> fixed, noise;
};

Pair roomLike(unsigned seed) {
  Pair p{std::vector<float>(kLength, 0.f), std::vector<float>(kLength, 0.f)};
  p.fixed[960] = 1.f;
  p.fixed[1100] = -0.4f;
  p.fixed[1500] = 0.3f;
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.f, 1.f);
  for (size_t t = 1056; t < kLength; ++t)
    if (t < 1490 || t > 1510) p.noise[t] = 0.08f * g(rng) * std::exp(-6.9f * float(t) / kFs);
  return p;
}

}  // namespace

TEST_CASE("Noise orthogonal to the fixed part: no cross term in any levelled octave band",
          "[synthesis]") {
  NoiseOrthogonaliser ortho(kFs, kLength, kFirst, kLast);
  for (unsigned seed : {1u, 2u, 3u}) {
    Pair p = roomLike(seed);
    // Before: the direct sound and the early noise overlap in the low bands' filters, and one
    // realisation's cross term is several per cent of a band's energy in at least one band.
    double before = 0.0;
    for (int b = kFirst; b <= kLast; ++b) before = std::max(before, std::abs(relativeCross(p.fixed, p.noise, b)));
    CHECK(before > 0.01);
    const std::vector<float> original = p.noise;
    ortho.apply(p.noise.data(), p.fixed.data());
    for (int b = kFirst; b <= kLast; ++b) {
      INFO("seed " << seed << " band " << kBandCentreHz[size_t(b)] << " Hz");
      // The FFT kernel's truncation (kRingOut 1e-6 of the impulse energy) and float rounding
      // leave far less than 0.1 % of a band's energy.
      CHECK(std::abs(relativeCross(p.fixed, p.noise, b)) < 1e-3);
    }
    // The support is kept: cleared samples stay zero; nothing changes before the noise starts.
    double removed = 0.0, energy = 0.0;
    for (size_t t = 0; t < kLength; ++t) {
      if (original[t] == 0.f) REQUIRE(p.noise[t] == 0.f);
      removed += double(p.noise[t] - original[t]) * (p.noise[t] - original[t]);
      energy += double(original[t]) * original[t];
    }
    // At most kLast - kFirst + 1 = 5 degrees of freedom go, out of the noise's thousands near
    // the fixed part: well under 1 % of its energy.
    CHECK(removed < 0.01 * energy);
    CHECK(removed > 0.0);
  }
}

TEST_CASE("Noise orthogonaliser: no fixed part, or no noise, changes nothing", "[synthesis]") {
  NoiseOrthogonaliser ortho(kFs, kLength, kFirst, kLast);
  Pair p = roomLike(4);
  const std::vector<float> original = p.noise;
  const std::vector<float> none(kLength, 0.f);
  ortho.apply(p.noise.data(), none.data());
  CHECK(p.noise == original);
  std::vector<float> silent(kLength, 0.f);
  ortho.apply(silent.data(), p.fixed.data());
  CHECK(silent == none);
}
