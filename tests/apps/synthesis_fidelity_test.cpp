// The IR synthesis adds no error to band parameters: the ISO 3382-1 band analysis of a
// synthesised IR (Butterworth octave filters, analysis/room_parameters.h) returns the parameters
// and level of the energy response it was made from, and the IR's band decay curve through
// those filters follows the energy response's.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "analysis/room_parameters.h"
#include "synthesis/mono_synthesizer.h"
#include "common/octave_filter.h"
#include "testing/test_util.h"
#include "tests/apps/band_readings.h"

using namespace dpc;
using test::strengthDbOf;

namespace {

constexpr int kFs = 48000;

/// An exponential decay per band from 5 ms on, T60 per band, plus a direct sound at 3 ms
/// (bin start, so that the energy analysis and the IR's onset agree to the sample).
struct Case {
  EnergyResponse er;
  DirectSound direct;
  Bands t60;
};

Case makeCase(double length, const Bands& t60, float directIntensity) {
  Case c{EnergyResponse(length, 1e-3), DirectSound{}, t60};
  for (size_t k = 5; k < c.er.binCount(); ++k) {
    const double t = (double(k) + 0.5) * 1e-3;
    for (int b = 0; b < kNumBands; ++b)
      c.er.bins()[k][b] = float(2e-4 * std::pow(10.0, -6.0 * t / t60[b]));
  }
  c.direct.visible = true;
  c.direct.delaySeconds = 0.003f;
  c.direct.distance = 0.003f * 343.f;
  c.direct.intensity = Bands(directIntensity);
  return c;
}

/// The IR synthesised at kFs from er and d (an IrSynthesizer of that length, room volume and
/// seed).
std::vector<float> synthesise(const EnergyResponse& er, const DirectSound& d, double length,
                              double volume, uint64_t seed) {
  IrSynthesizer synth(kFs, length, volume, 343.0, seed);
  std::vector<float> ir(synth.lengthSamples());
  synth.synthesize(er, d, ir.data());
  return ir;
}

/// Seeds of the synthesis: the IR is one noise realisation, so its band readings scatter as any
/// noise IR's do (one realisation of a 1 s decay in the 250 Hz octave has about
/// 2 B T60 / 6.9 = 60 degrees of freedom: 0.8 dB rms in level). The tests bound the bias: the
/// mean over the seeds within 3 standard errors (estimated from the seeds) plus what the
/// analysis itself does to any IR.
constexpr uint64_t kSeeds = 8;

/// Mean and standard error of the per-seed values.
std::pair<double, double> overSeeds(const std::vector<double>& v) {
  return test::meanAndStandardError(v);
}

}  // namespace

TEST_CASE("Synthesised IR: band decay curve on the analysis filters follows the energy response's",
          "[synthesis]") {
  Bands t60;
  for (int b = 0; b < kNumBands; ++b) t60[b] = 1.4f - 0.12f * float(b);
  const double length = 1.5;
  const Case c = makeCase(length, t60, 0.f);
  // Per band: the Schroeder curve's deviation from the response's every 10 ms from 20 ms on
  // while the response's curve is above -30 dB, and the band's level, per seed.
  std::array<std::vector<std::vector<double>>, kNumBands> curve;
  std::array<std::vector<double>, kNumBands> level;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    IrSynthesizer synth(kFs, length, 200.0, 343.0, seed);
    std::vector<float> ir(synth.lengthSamples());
    synth.synthesize(c.er, DirectSound{}, ir.data());
    for (int b = 0; b < kNumBands; ++b) {
      const OctaveBandPass filter = OctaveBandPass::design(bandCentreExactHz(b), kFs);
      OctaveBandPass::State st{};
      std::vector<double> y(ir.size());
      filter.run(ir.data(), y.data(), ir.size(), st);
      std::vector<double> tailIr(ir.size() + 1, 0.0), tailEr(c.er.binCount() + 1, 0.0);
      // On the response's scale: a band value is a spectral density, read through the filter
      // relative to a unit impulse (the free-field reference).
      const double unit = filter.impulseEnergy(size_t(kFs));
      for (size_t n = ir.size(); n-- > 0;) tailIr[n] = tailIr[n + 1] + y[n] * y[n] / unit;
      for (size_t k = c.er.binCount(); k-- > 0;) tailEr[k] = tailEr[k + 1] + c.er.bins()[k][b];
      std::vector<double> deviation;
      for (size_t ms = 20; tailEr[ms] > 1e-3 * tailEr[0]; ms += 10)
        deviation.push_back(10 * std::log10(tailIr[ms * size_t(kFs) / 1000] / tailIr[0]) -
                            10 * std::log10(tailEr[ms] / tailEr[0]));
      curve[size_t(b)].push_back(deviation);
      level[size_t(b)].push_back(10 * std::log10(tailIr[0] / tailEr[0]));
    }
  }
  for (int b = 0; b < kNumBands; ++b) {
    // The curve: the mean over the seeds within 3 standard errors plus 0.5 dB at every point
    // (the filter's energy delay, 16 ms at 63 Hz halving per octave, shifts any IR's curve
    // against the response's; 1 dB at 63 and 125 Hz, whose filters ring longest).
    double worst = 0.0;
    for (size_t i = 0; i < curve[size_t(b)][0].size(); ++i) {
      std::vector<double> at;
      for (const auto& d : curve[size_t(b)]) at.push_back(d[i]);
      const auto [m, se] = overSeeds(at);
      worst = std::max(worst, std::abs(m) - 3 * se);
    }
    const auto [l, lse] = overSeeds(level[size_t(b)]);
    std::printf("decay curve band %4d Hz: worst mean deviation beyond 3 SE %.3f dB; level %+.3f "
                "+- %.3f dB\n", int(kBandCentreHz[size_t(b)]), worst, l, lse);
    INFO("band " << b);
    CHECK(worst < (b >= 2 ? 0.5 : 1.0));
    // Level: the band's total energy (strength G) as the response's within 3 standard errors
    // plus 0.1 dB (0.3 dB at 63 Hz, where the IR's end truncates the filter's ringing).
    CHECK(std::abs(l) < 3 * lse + (b == 0 ? 0.3 : 0.1));
  }
}

TEST_CASE("Synthesised IR: ISO 3382-1 band analysis returns the energy response's T30 and C80",
          "[synthesis]") {
  Bands t60;
  for (int b = 0; b < kNumBands; ++b) t60[b] = 1.3f - 0.1f * float(b);
  const double length = 2.0;
  const Case c = makeCase(length, t60, 2e-3f);
  // The response's parameters, and what the same band analysis reads from an exact IR of this
  // response, in expectation.
  const test::ResponseBands bands(c.er, c.direct, kFs);
  std::array<std::vector<double>, kNumBands> t30, c80, g;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const std::vector<float> ir = synthesise(c.er, c.direct, length, 200.0, seed);
    for (const auto& [b, want, asMeasured, got] : bands.read(ir, 0)) {
      t30[size_t(b)].push_back(got.t30 / want.t30 - 1);
      c80[size_t(b)].push_back(got.c80 - want.c80);
      g[size_t(b)].push_back(strengthDbOf(got) - strengthDbOf(want));
    }
  }
  for (int b = 0; b < kNumBands; ++b) {
    const audio::RoomParameters &want = bands.response(b), &exact = bands.exactIr(b);
    const auto [mt, st] = overSeeds(t30[size_t(b)]);
    const auto [mc, sc] = overSeeds(c80[size_t(b)]);
    const auto [mg, sg] = overSeeds(g[size_t(b)]);
    std::printf("band %4d Hz over %d seeds: T30 %+.2f +- %.2f %%, C80 %+.3f +- %.3f dB (exact IR "
                "%+.3f), G %+.3f +- %.3f dB\n",
                int(kBandCentreHz[size_t(b)]), int(kSeeds), 100 * mt, 100 * st, mc, sc,
                exact.c80 - want.c80, mg, sg);
    INFO("band " << b);
    // T30: within 3 standard errors plus 1 % (2.5 % at 63 Hz, whose filter's ringing biases
    // short decays, room_parameters.h). C80: plus 0.2 dB or, where the octave filters' energy
    // delay moves early energy past 80 ms in any IR (an exact IR of this response reads C80
    // 1.4, 0.7, 0.4 dB low at 63/125/250 Hz), no further off than the exact IR, plus 0.2 dB.
    // G: plus 0.1 dB (0.3 dB at 63 Hz).
    CHECK(std::abs(mt) < 3 * st + (b >= 1 ? 0.01 : 0.025));
    CHECK(std::abs(mc) < 3 * sc + std::max(0.2, std::abs(exact.c80 - want.c80) + 0.2));
    CHECK(std::abs(mg) < 3 * sg + (b == 0 ? 0.3 : 0.1));
  }
}

TEST_CASE(
    "Synthesised IR: a band decaying far faster than the band below reads no longer than "
    "an exact IR",
    "[synthesis]") {
  // A large hall's decay: air absorption makes 4 kHz and 8 kHz decay much faster than 2 kHz
  // (T60 2.6, 2.0, 1.0 s), so late in the decay the 8 kHz band lies 40-60 dB below 2 kHz.
  // Every gain step of the slower bands' synthesis splatters broadband some 40-60 dB below
  // them; unless cleaned up (IrSynthesizer::cleanUp) that splatter, not the band, is what the
  // 8 kHz analysis filter measures (T30 read 2.4 times the response's in scenes/hall.json).
  // An exact IR of the response is read long as well, through the filter's skirt (the slower
  // 4 kHz octave's energy at its upper edge): the synthesised IR must read no longer than
  // that, within 3 % (the spread over seeds of the synthesis, measured +-1 %).
  const std::array<float, kNumBands> hall = {3.4f, 3.3f, 3.2f, 3.0f, 2.8f, 2.6f, 2.0f, 1.0f};
  Bands t60;
  for (int b = 0; b < kNumBands; ++b) t60[b] = hall[size_t(b)];
  const double length = 3.0;
  const Case c = makeCase(length, t60, 2e-3f);
  const test::ResponseBands bands(c.er, c.direct, kFs);
  for (uint64_t seed : {1u, 2u}) {
    const std::vector<float> ir = synthesise(c.er, c.direct, length, 8000.0, seed);
    for (const auto& [b, want, exact, got] : bands.read(ir, 5)) {
      std::printf(
          "seed %d band %4d Hz: T30 response %.3f, exact IR %.3f, synthesised %.3f; "
          "C80 %.2f / %.2f / %.2f dB\n",
          int(seed), int(kBandCentreHz[size_t(b)]), want.t30, exact.t30, got.t30, want.c80,
          exact.c80, got.c80);
      INFO("band " << b << " seed " << seed);
      CHECK(got.t30 < std::max(want.t30, exact.t30) * 1.03);
      CHECK(got.t30 > want.t30 * 0.97);
      // Early energy stays: C80 as in the other test, plus 0.5 dB: in 8000 m^3 the Dirac
      // sequence holds less than one pulse per 10 ms before 0.13 s, so C80 scatters from seed
      // to seed (measured 0.26 and 0.67 dB off at 2 and 4 kHz in seed 1, the same without
      // the clean-up; at most 0.06 dB in seed 2).
      CHECK(std::abs(got.c80 - want.c80) < std::max(0.2, std::abs(exact.c80 - want.c80)) + 0.5);
    }
  }
}

TEST_CASE("An open scene's bounding volume: early energy stays early", "[synthesis]") {
  // 10^8 m^3 (a 2 km square open scene's bounding box): the density law alone gives the Dirac
  // sequence its first pulse about a second in, so the direct sound's neighbours (a ground
  // reflection 4 ms after it, the first 80 ms of scattering) would all wait for it and C80
  // would turn from clearly positive to negative (measured -3 to -4 dB in an open test scene
  // whose exact IR reads +21 to +85 dB). The density floor (kMinPulseDensity) keeps a pulse
  // within about 10 ms, so over the seeds no band's C80 may fall more than 3 standard errors
  // plus 1 dB below an exact IR's, and G stays within 3 standard errors plus 0.5 dB (a sparse
  // sequence's few pulses carry the late part: one seed reads up to 2.5 dB off at 125 Hz).
  const double length = 1.5;
  EnergyResponse er(length, 1e-3);
  DirectSound d;
  d.visible = true;
  d.delaySeconds = 0.010f;
  d.intensity = Bands(1e-3f);
  er.bins()[14] = Bands(6e-4f);  // ground reflection
  for (size_t k = 15; k < er.binCount(); ++k)  // scattering, T60 0.8 s
    er.bins()[k] = Bands(float(2e-5 * std::pow(10.0, -6.0 * double(k) * 1e-3 / 0.8)));
  const test::ResponseBands bands(er, d, kFs);
  std::array<std::vector<double>, kNumBands> c80, g;
  for (uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const std::vector<float> ir = synthesise(er, d, length, 1e8, seed);
    for (const test::BandReading& r : bands.read(ir, 1)) {
      c80[size_t(r.band)].push_back(r.ir.c80 - r.exactIr.c80);
      g[size_t(r.band)].push_back(10 * std::log10(r.ir.energy / r.exactIr.energy));
    }
  }
  for (int b = 1; b < kNumBands; ++b) {
    const auto [mc, sc] = overSeeds(c80[size_t(b)]);
    const auto [mg, sg] = overSeeds(g[size_t(b)]);
    std::printf("open scene band %4d Hz over %d seeds: C80 - exact %+.2f +- %.2f dB, G - exact "
                "%+.2f +- %.2f dB\n",
                int(kBandCentreHz[size_t(b)]), int(kSeeds), mc, sc, mg, sg);
    INFO("band " << b);
    CHECK(mc > -(3 * sc + 1.0));
    CHECK(std::abs(mg) < 3 * sg + 0.5);
  }
}
