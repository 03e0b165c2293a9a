// The IR synthesis adds no error to band parameters: the ISO 3382-1 band analysis of a
// synthesised IR (Butterworth octave filters, analysis/room_parameters.h) returns the parameters
// and level of the energy response it was made from, and the IR's band decay curve through
// those filters follows the energy response's.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <vector>

#include "analysis/room_parameters.h"
#include "synthesis/mono_synthesizer.h"
#include "common/octave_filter.h"
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

}  // namespace

TEST_CASE("Synthesised IR: band decay curve on the analysis filters follows the energy response's",
          "[synthesis]") {
  Bands t60;
  for (int b = 0; b < kNumBands; ++b) t60[b] = 1.4f - 0.12f * float(b);
  const double length = 1.5;
  const Case c = makeCase(length, t60, 0.f);
  // Seeds: the claim is per realisation, not on average.
  for (uint64_t seed : {1u, 2u, 3u}) {
    IrSynthesizer synth(kFs, length, 200.0, 343.0, seed);
    std::vector<float> ir(synth.lengthSamples());
    synth.synthesize(c.er, DirectSound{}, ir.data());
    for (int b = 0; b < kNumBands; ++b) {
      // Schroeder curves (backward-integrated energy, dB re the total) of the energy response
      // and of the IR through the ISO 3382-1 octave filter, every 10 ms from 20 ms on while
      // the response's curve is above -30 dB.
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
      double worst = 0.0;
      for (size_t ms = 20; tailEr[ms] > 1e-3 * tailEr[0]; ms += 10) {
        const double lEr = 10 * std::log10(tailEr[ms] / tailEr[0]);
        const double lIr = 10 * std::log10(tailIr[ms * size_t(kFs) / 1000] / tailIr[0]);
        worst = std::max(worst, std::abs(lIr - lEr));
      }
      // Measured over these seeds (docs/validation.md): worst 0.13-0.24 dB from 2 to 8 kHz,
      // 0.4-0.8 dB at 250 Hz-1 kHz, 1.8 dB at 63/125 Hz. What limits it: the synthesis
      // matches the filter's cumulative output at bin ends (1 ms ... 32 ms), each bin charged
      // with its ringing, so between bin ends and by the ringing still to come (energy delay
      // 16 ms at 63 Hz, halving per octave) the curves differ; low bands have few degrees of
      // freedom per bin (bandwidth x bin length ~ 1.4).
      std::printf("decay curve: seed %d band %4d Hz  worst %.3f dB\n", int(seed),
                  int(kBandCentreHz[size_t(b)]), worst);
      INFO("seed " << seed << " band " << b);
      CHECK(worst < (b >= 2 ? 1.0 : 2.5));
      // Level: the band's total energy (strength G) as the response's: measured within
      // 0.07 dB from 125 Hz up, 0.2 dB at 63 Hz (the IR's end truncates the filter's ringing).
      CHECK(std::abs(10 * std::log10(tailIr[0] / tailEr[0])) < (b == 0 ? 0.3 : 0.1));
      std::printf("  level %+.3f dB, missing energy %.3g of %.3g\n",
                  10 * std::log10(tailIr[0] / tailEr[0]), synth.missingEnergy()[b], tailEr[0]);
    }
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
  for (int b = 0; b < kNumBands; ++b) {
    const audio::RoomParameters &want = bands.response(b), &m = bands.exactIr(b);
    std::printf("exact IR, band %4d Hz: T30 %+.2f %% EDT %+.2f %% C80 %+.3f dB G %+.3f dB\n",
                int(kBandCentreHz[size_t(b)]), 100 * (m.t30 / want.t30 - 1),
                100 * (m.edt / want.edt - 1), m.c80 - want.c80,
                strengthDbOf(m) - strengthDbOf(want));
  }
  for (uint64_t seed : {1u, 2u, 3u}) {
    const std::vector<float> ir = synthesise(c.er, c.direct, length, 200.0, seed);
    for (const auto& [b, want, asMeasured, got] : bands.read(ir, 0)) {
      std::printf(
          "seed %d band %4d Hz: T30 %.3f/%.3f (%+.2f %%) T20 %+.2f %% EDT %+.2f %% C80 %+.3f dB "
          "C50 %+.3f dB D50 %+.4f G %+.3f dB\n",
          int(seed), int(kBandCentreHz[size_t(b)]), got.t30, want.t30,
          100 * (got.t30 / want.t30 - 1), 100 * (got.t20 / want.t20 - 1),
          100 * (got.edt / want.edt - 1), got.c80 - want.c80, got.c50 - want.c50,
          got.d50 - want.d50, strengthDbOf(got) - strengthDbOf(want));
      // Measured over these 3 seeds (docs/validation.md): T30 within 0.63 % from 125 Hz to
      // 8 kHz, 1.8 % at 63 Hz; C80 within 0.19 dB from 500 Hz to 8 kHz, 0.32 dB at 125/250 Hz,
      // 1.7 dB at 63 Hz. The same analysis of an exact IR of this response (asMeasured:
      // expectedBandAnalysisEnergy) reads C80 1.37, 0.74, 0.39 dB low at 63/125/250 Hz: the
      // octave filters' energy delay (16 ms at 63 Hz, halving per octave) moves early energy
      // past 80 ms in any IR. So C80 must be within 0.2 dB or, where the filters alone move
      // it further, no further off than the exact IR; 63 Hz gets 0.5 dB more, its 32 ms
      // synthesis bins holding about 1.4 degrees of freedom each.
      INFO("band " << b << " seed " << seed);
      CHECK(std::abs(got.t30 / want.t30 - 1) < (b >= 1 ? 0.01 : 0.025));
      CHECK(std::abs(got.c80 - want.c80) <
            std::max(0.2, std::abs(asMeasured.c80 - want.c80)) + (b == 0 ? 0.5 : 0.0));
      CHECK(std::abs(strengthDbOf(got) - strengthDbOf(want)) < (b == 0 ? 0.3 : 0.1));
    }
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
  // within about 10 ms, so no band's C80 may fall more than 1 dB below an exact IR's (measured
  // at most 0.3 dB below, seeds 1-3, 125 Hz-8 kHz). What the sparse sequence still does: the
  // refinement cannot give the late part its full energy where pulses are 10 ms apart, so
  // C80 reads high (measured up to +21 dB above the exact IR's +9 dB) and G up to 2.7 dB
  // high; asserted only as a bound (G within 3 dB), see docs/validation.md.
  const double length = 1.5;
  for (uint64_t seed : {1u, 2u, 3u}) {
    EnergyResponse er(length, 1e-3);
    DirectSound d;
    d.visible = true;
    d.delaySeconds = 0.010f;
    d.intensity = Bands(1e-3f);
    er.bins()[14] = Bands(6e-4f);  // ground reflection
    for (size_t k = 15; k < er.binCount(); ++k)  // scattering, T60 0.8 s
      er.bins()[k] = Bands(float(2e-5 * std::pow(10.0, -6.0 * double(k) * 1e-3 / 0.8)));
    const std::vector<float> ir = synthesise(er, d, length, 1e8, seed);
    for (const test::BandReading& r : test::ResponseBands(er, d, kFs).read(ir, 1)) {
      const int b = r.band;
      const audio::RoomParameters &exact = r.exactIr, &got = r.ir;
      const double dG = 10 * std::log10(got.energy / exact.energy);
      std::printf("open scene seed %d band %4d Hz: C80 %+.2f (exact %+.2f) dB, G %+.2f dB\n",
                  int(seed), int(kBandCentreHz[size_t(b)]), got.c80, exact.c80, dG);
      INFO("seed " << seed << " band " << b);
      CHECK(got.c80 > exact.c80 - 1.0);
      CHECK(std::abs(dG) < 3.0);
    }
  }
}
