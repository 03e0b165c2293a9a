// The arrivals' placement (synthesis/arrival_placer.h): the low bands summed on FFT bins, the
// high bands tap by tap.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "common/fftw_util.h"
#include "common/octave_band_masks.h"
#include "synthesis/arrival_placer.h"
#include "synthesis/band_filters.h"

using namespace dpc;

namespace {

constexpr int kRate = 48000;

struct Filters {
  size_t length, n;
  std::shared_ptr<const DirectSoundFilter> direct;
  std::unique_ptr<ArrivalPlacer> placer;
  explicit Filters(size_t irLength) : length(irLength) {
    const size_t taps = bandFilterTaps(kRate);
    n = smoothFftSize(length + taps);
    FftwRealTransforms fft(n);
    const OctaveBandMasks masks(kRate, n);
    direct = std::make_shared<const DirectSoundFilter>(masks, fft, taps);
    placer = std::make_unique<ArrivalPlacer>(masks, direct, n);
  }
};

double peak(const std::vector<float>& x) {
  double m = 0.0;
  for (float v : x) m = std::max(m, double(std::abs(v)));
  return m;
}

}  // namespace

// Oracle: every band's filter added tap by tap at the arrival's sample (the plain convolution of
// each band's arrival train with a_b). Arrivals at random delays (some whose pulses reach past
// either end of the IR or miss it) and random band intensities. Tolerance: the filters drop
// taps holding -100 dB of a band's energy each side, at most 1e-5 of a band's peak per sample
// from each of 40 arrivals, and float rounding of an FFT of 2^15 points (~1e-6 relative):
// 1e-4 of the IR's peak.
TEST_CASE("Arrivals placed on bins equal the band filters added tap by tap", "[synthesis]") {
  Filters f(10965);
  REQUIRE(f.placer->split() > 0);  // the long low-band filters go through the spectrum
  REQUIRE(f.placer->split() < kNumBands);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> delay(-0.2, double(f.length) / kRate + 0.2);
  std::uniform_real_distribution<float> level(0.f, 1.f);
  std::vector<Arrival> arrivals(40);
  for (Arrival& a : arrivals) {
    a.delaySeconds = delay(rng);
    for (int b = 0; b < kNumBands; ++b) a.intensity[b] = level(rng) * level(rng);
  }
  arrivals[0].delaySeconds = 0.0;
  arrivals[1].delaySeconds = double(f.length - 1) / kRate;
  std::vector<float> placed(f.length, 0.f), reference(f.length, 0.f);
  f.placer->place(arrivals, kRate, placed.data(), f.length);
  const long centre = long(f.direct->centre());
  for (const Arrival& a : arrivals) {
    const long n0 = std::lround(a.delaySeconds * kRate);
    for (int b = 0; b < kNumBands; ++b)
      f.direct->add(b, std::sqrt(a.intensity[b]), n0 - centre, reference.data(), f.length);
  }
  double worst = 0.0;
  for (size_t i = 0; i < f.length; ++i)
    worst = std::max(worst, double(std::abs(placed[i] - reference[i])));
  const double scale = peak(reference);
  REQUIRE(scale > 0.1);
  CHECK(worst <= 1e-4 * scale);
}

// Oracle: the band filters are amplitude-complementary (sum_b A_b = 1), so an arrival with the
// same intensity in every band is a single sample of amplitude sqrt(I) and nothing else,
// whichever part of the bands the bins carry. Tolerance as above, 1e-4 of the pulse.
TEST_CASE("A white arrival is one sample at its delay", "[synthesis]") {
  Filters f(4000);
  for (long n0 : {0L, 1L, 1234L, 3999L}) {
    Arrival a;
    a.delaySeconds = double(n0) / kRate;
    a.intensity = Bands(0.25f);
    std::vector<float> ir(f.length, 0.f);
    f.placer->place(std::span<const Arrival>(&a, 1), kRate, ir.data(), f.length);
    CHECK(std::abs(ir[size_t(n0)] - 0.5f) <= 0.5e-4);
    ir[size_t(n0)] = 0.f;
    CHECK(peak(ir) <= 0.5e-4);
  }
}

// An arrival whose pulse lies wholly outside the IR adds nothing: one just short of the FFT's
// length would otherwise wrap its ringing round into the IR's start.
TEST_CASE("An arrival far past the IR adds nothing", "[synthesis]") {
  Filters f(4000);
  Arrival a;
  a.delaySeconds = double(f.n - 100) / kRate;
  a.intensity = Bands(1.f);
  std::vector<float> ir(f.length, 0.f);
  f.placer->place(std::span<const Arrival>(&a, 1), kRate, ir.data(), f.length);
  CHECK(peak(ir) == 0.0);
}
