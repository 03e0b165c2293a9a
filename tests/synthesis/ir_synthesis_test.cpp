#include <fftw3.h>

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "common/octave_filter.h"
#include "synthesis/band_envelope.h"
#include "synthesis/band_filters.h"
#include "synthesis/mono_synthesizer.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using dpc::test::bandEnergies;

using namespace dpc;

namespace {

double db(double x) {
  return 10.0 * std::log10(x);
}

/// Band energies of x through the ISO 3382-1 octave filters (common/octave_filter.h), with
/// 0.5 s of silence after it so that the filters ring out, over what a unit impulse gives
/// (the free-field reference through the same filter): on the energy response's scale, where
/// a band value is a spectral density.
Bands analysisBandEnergies(const std::vector<float>& x, int fs) {
  Bands out;
  for (int b = 0; b < kNumBands; ++b) {
    const OctaveBandPass f = OctaveBandPass::design(bandCentreExactHz(b), fs);
    OctaveBandPass::State st{};
    double e = 0.0;
    for (size_t n = 0; n < x.size() + size_t(fs / 2); ++n) {
      const double y = f.step(n < x.size() ? double(x[n]) : 0.0, st);
      e += y * y;
    }
    out[b] = float(e / f.impulseEnergy(size_t(fs)));
  }
  return out;
}

/// A 1 s response in 1 ms bins decaying exponentially (T60 0.5 s) in every band from bin
/// `firstBin` on, empty before.
EnergyResponse exponentialDecay(size_t firstBin) {
  EnergyResponse er(1.0, 1e-3);
  for (size_t k = firstBin; k < er.binCount(); ++k)
    er.bins()[k] = Bands(1e-4f * std::exp(-13.8f * float(k) * 1e-3f));
  return er;
}

/// A 1.5 s reverberant tail in 1 ms bins with a band-dependent decay (t60: from 1.6 s at 63 Hz
/// to 0.4 s at 8 kHz), starting at 8 ms.
EnergyResponse bandDependentDecay(Bands& t60) {
  EnergyResponse er(1.5, 1e-3);
  for (int b = 0; b < kNumBands; ++b) t60[b] = 1.6f - 0.17f * b;
  for (size_t k = 8; k < er.binCount(); ++k) {
    const double t = (k + 0.5) * 1e-3;
    for (int b = 0; b < kNumBands; ++b)
      er.bins()[k][b] = float(1e-3 * std::pow(10.0, -6.0 * t / t60[b]));
  }
  return er;
}

/// The IR synth makes of er with no direct sound.
std::vector<float> synthesizeWithoutDirect(IrSynthesizer& synth, const EnergyResponse& er) {
  std::vector<float> ir(synth.lengthSamples());
  synth.synthesize(er, DirectSound{}, ir.data());
  return ir;
}

size_t nonFiniteCount(const std::vector<float>& x) {
  size_t n = 0;
  for (float v : x) n += std::isfinite(v) ? 0 : 1;
  return n;
}

}  // namespace

TEST_CASE("Octave masks are power-complementary", "[ir]") {
  OctaveBandMasks m(48000, 4096);
  for (size_t k = 0; k < m.binCount(); ++k) {
    double s = 0;
    for (int b = 0; b < kNumBands; ++b) s += double(m.gain(b, k)) * m.gain(b, k);
    REQUIRE(s == Approx(1.0).margin(1e-5));
  }
}

TEST_CASE("Synthesised IR has the energy response's band energies", "[ir][statistics]") {
  const int fs = 48000;
  Bands t60;
  const EnergyResponse er = bandDependentDecay(t60);
  const Bands want = er.total();
  // Band energy measured through the ISO 3382-1 octave filters (not the synthesiser's own
  // masks, which reach beyond the analysed octaves at 63 Hz and 8 kHz). The synthesis is
  // unbiased: the mean of 10 sequences within 3 standard errors plus 0.1 dB.
  const int seeds = 10;
  std::array<std::vector<double>, kNumBands> ratios;
  std::array<std::vector<double>, kNumBands> drops;
  for (int seed = 1; seed <= seeds; ++seed) {
    IrSynthesizer synth(fs, 1.5, 210.0, 343.0, uint64_t(seed));
    const std::vector<float> ir = synthesizeWithoutDirect(synth, er);
    const Bands got = analysisBandEnergies(ir, fs);
    for (int b = 0; b < kNumBands; ++b) ratios[size_t(b)].push_back(got[b] / want[b]);
    // The decay survives: band energy in [0.2, 0.3) s against [0.6, 0.7) s.
    std::vector<float> early(ir.begin() + fs / 5, ir.begin() + 3 * fs / 10);
    std::vector<float> late(ir.begin() + 6 * fs / 10, ir.begin() + 7 * fs / 10);
    const Bands e = bandEnergies(early, fs), l = bandEnergies(late, fs);
    for (int b = 3; b < kNumBands; ++b) drops[size_t(b)].push_back(db(e[b]) - db(l[b]));
  }
  const auto meanAndError = test::meanAndStandardError;
  for (int b = 0; b < kNumBands; ++b) {
    const auto [m, se] = meanAndError(ratios[size_t(b)]);
    INFO("band " << b << ": IR / energy response = " << db(m) << " dB +- " << se);
    CHECK(std::abs(m - 1.0) < 3 * se + 0.023);  // 0.1 dB
  }
  // One realisation of the realised bands (63, 125 Hz) spreads less than noise of that band
  // and decay would: an unnormalised realisation has about 2 B T60 / 6.9 degrees of freedom
  // (B the filter's noise bandwidth, 46 Hz at 63 Hz; T60 1.6 s: 21), a relative spread of
  // sqrt(2 / 21) = 1.3 dB rms. The realised normalisation holds each synthesis bin's band
  // energy within the analysed octave; what the analysis filter's skirts see of the
  // neighbours and below 44 Hz still varies. Required: rms spread over the seeds below half
  // the unnormalised one, and every seed within 3 times that bound.
  for (int b = 0; b < BandEnvelope::kRealisedBands; ++b) {
    const double noiseBandwidth = 1.047 * bandCentreExactHz(b) / std::sqrt(2.0);
    const double dof = 2.0 * noiseBandwidth * double(t60[b]) / 6.9;
    const double unnormalisedDb = 10.0 * std::log10(1.0 + std::sqrt(2.0 / dof));
    double ss = 0.0;
    for (double r : ratios[size_t(b)]) {
      INFO("band " << b << " single realisation " << db(r) << " dB");
      CHECK(std::abs(db(r)) < 1.5 * unnormalisedDb);
      ss += db(r) * db(r);
    }
    const double rms = std::sqrt(ss / double(seeds));
    INFO("band " << b << " realisation spread " << rms << " dB rms, unnormalised " << unnormalisedDb
                 << " dB");
    CHECK(rms < 0.5 * unnormalisedDb);
  }
  // Windowed decay at 500 Hz and 1 kHz (100 ms windows hold enough cycles; from 2 kHz up the
  // expected drop, 32-59 dB, reaches the leakage floor of a rectangular window through which
  // the slower lower bands spill, ~ -35 dB): expected 60 * 0.4 / T60 dB; allowance 1 dB for
  // the window edges cutting the band filters' responses.
  for (int b = 3; b <= 4; ++b) {
    const auto [m, se] = meanAndError(drops[size_t(b)]);
    const double expectDrop = 60.0 * 0.4 / t60[b];
    INFO("band " << b << " drop " << m << " dB +- " << se << ", expected " << expectDrop);
    CHECK(std::abs(m - expectDrop) < 3 * se + 1.0);
  }
}

TEST_CASE("Direct sound lands at its delay, silence gives silence", "[ir]") {
  const int fs = 48000;
  IrSynthesizer synth(fs, 0.5, 100.0, 343.0, 3);
  EnergyResponse er(0.5, 1e-3);
  DirectSound d;
  d.visible = true;
  d.delaySeconds = 0.0123f;
  d.intensity = Bands(0.01f);
  std::vector<float> ir(synth.lengthSamples());
  synth.synthesize(er, d, ir.data());
  size_t peak = 0;
  for (size_t i = 0; i < ir.size(); ++i)
    if (std::abs(ir[i]) > std::abs(ir[peak])) peak = i;
  CHECK(long(peak) == std::lround(0.0123 * fs));
  // The direct sound is deterministic: its band energies equal DirectSound::intensity within
  // 0.25 dB (the filters' tails cut at the IR's start and end, and the crossovers between
  // bands of unequal amplitude).
  d.intensity = Bands(0.f);
  for (int b = 0; b < kNumBands; ++b) d.intensity[b] = 0.02f / float(b + 1);
  synth.synthesize(er, d, ir.data());
  const Bands got = bandEnergies(ir, fs);
  for (int b = 0; b < kNumBands; ++b) {
    INFO("band " << b << ": " << db(got[b] / d.intensity[b]) << " dB");
    CHECK(std::abs(db(got[b] / d.intensity[b])) < 0.25);
  }
  d.visible = false;
  synth.synthesize(er, d, ir.data());
  for (float x : ir) REQUIRE(x == 0.f);
}

TEST_CASE("A negative rounding residue in a bin gives a finite IR", "[ir]") {
  // An exponential decay per band, the 8 kHz band empty around 0.7 s but for one bin holding
  // -1.76e-24 (the residue a sliding window's add-then-subtract can leave), must synthesise to
  // finite samples, as if it were 0.
  const int fs = 48000;
  IrSynthesizer synth(fs, 1.0, 500.0, 343.0, 7);
  EnergyResponse er = exponentialDecay(0);
  for (size_t k = 650; k < 750; ++k) er.bins()[k][7] = 0.f;  // a sparse late 8 kHz band
  er.bins()[700][7] = -1.76e-24f;
  CHECK(nonFiniteCount(synthesizeWithoutDirect(synth, er)) == 0);
}

TEST_CASE("Sample rates whose Nyquist cuts the top octaves synthesise the bands below", "[ir]") {
  // At 16 and 22.05 kHz the 8 kHz octave (to 11.3 kHz) lies above Nyquist, so its analysis
  // filter does not exist and the band is not cleaned; the bands that fit carry the response's
  // band energy through their analysis filters as at 48 kHz: the mean over 8 sequences within
  // 3 standard errors plus 0.1 dB (one realisation of a 0.5 s decay spreads about 0.5 dB).
  const EnergyResponse er = exponentialDecay(5);
  for (int fs : {16000, 22050}) {
    std::array<std::vector<double>, kNumBands> ratios;
    for (uint64_t seed = 1; seed <= 8; ++seed) {
      IrSynthesizer synth(fs, 1.0, 300.0, 343.0, seed);
      const std::vector<float> ir = synthesizeWithoutDirect(synth, er);
      REQUIRE(nonFiniteCount(ir) == 0);
      const Bands got = analysisBandEnergies(ir, fs);
      for (int b = 1; b < kNumBands; ++b) {
        double want = 0.0;
        for (size_t k = 0; k < er.binCount(); ++k) want += er.bins()[k][b];
        ratios[size_t(b)].push_back(got[b] / want);
      }
    }
    for (int b = 1; b < kNumBands; ++b) {
      if (bandCentreExactHz(b) * std::sqrt(2.0) >= 0.5 * fs) continue;
      const auto [m, se] = test::meanAndStandardError(ratios[size_t(b)]);
      INFO("fs " << fs << " band " << b << ": IR / response " << db(m) << " dB +- " << se);
      CHECK(std::abs(m - 1.0) < 3 * se + 0.023);  // 0.1 dB
    }
  }
}

TEST_CASE("A frequency-independent arrival is a Dirac of its energy", "[ir]") {
  // A band value is a spectral density: the same value I in every band is a flat spectrum, so
  // the direct sound (or an exact path) must be a single sample of amplitude sqrt(I) at its
  // delay, as the dry signal passes an anechoic scene unchanged but for 1/r and the delay. The
  // band filters sum to 1 to float rounding (their FFT size leaves taps of 1e-7 relative).
  const int fs = 48000;
  IrSynthesizer synth(fs, 0.5, 100.0, 343.0, 5);
  const EnergyResponse silent(0.5, 1e-3);
  DirectSound d;
  d.visible = true;
  d.delaySeconds = 0.0071f;
  const double r = 0.0071 * 343.0;
  d.intensity = Bands(float(1.0 / (4.0 * 3.14159265358979323846 * r * r)));
  std::vector<float> ir(synth.lengthSamples());
  synth.synthesize(silent, d, ir.data());
  const long n0 = std::lround(0.0071 * fs);
  double rest = 0.0;
  for (size_t n = 0; n < ir.size(); ++n)
    if (long(n) != n0) rest += double(ir[n]) * ir[n];
  CHECK(ir[size_t(n0)] == Approx(std::sqrt(d.intensity[0])).epsilon(1e-5));
  CHECK(rest < 1e-9 * d.intensity[0]);
}

TEST_CASE("The zero-phase ringing ahead of the first arrival is cut at -80 dB", "[ir]") {
  // A source 30 m away: direct sound at 87.5 ms. Ahead of it the zero-phase band filters ring
  // (a band pulse's taps reach up to 125 ms ahead, the band levelling's split wraps round the
  // IR); cutLeadingResidue zeroes the leading samples that hold at most -80 dB of the sound up
  // to 1 ms after the arrival, so that a partitioned convolver can skip them.
  const int fs = 48000;
  const double delay = 0.0875;
  const size_t onset = size_t(std::lround(delay * fs));
  IrSynthesizer synth(fs, 0.5, 210.0, 343.0, 5);
  DirectSound d;
  d.visible = true;
  d.delaySeconds = float(delay);
  const auto leadingZeros = [](const std::vector<float>& x) {
    size_t n = 0;
    while (n < x.size() && x[n] == 0.f) ++n;
    return n;
  };
  std::vector<float> ir(synth.lengthSamples());
  SECTION("A direct sound of unequal bands keeps its band energies") {
    // Unequal bands make a pulse that rings (equal ones sum to a Dirac): its band energies
    // through the ISO analysis filters within 0.25 dB of the intensities, as when nothing is
    // cut ("Direct sound lands at its delay"); the cut may take at most 1e-8 of them.
    for (int b = 0; b < kNumBands; ++b) d.intensity[b] = 0.02f / float(b + 1);
    synth.synthesize(EnergyResponse(0.5, 1e-3), d, ir.data());
    const size_t zeros = leadingZeros(ir);
    INFO("leading zeros " << zeros << " (" << 1e3 * double(zeros) / fs << " ms)");
    CHECK(zeros >= size_t(0.020 * fs));
    CHECK(zeros < onset);
    const Bands got = bandEnergies(ir, fs);
    for (int b = 0; b < kNumBands; ++b) {
      INFO("band " << b << ": " << db(got[b] / d.intensity[b]) << " dB");
      CHECK(std::abs(db(got[b] / d.intensity[b])) < 0.25);
    }
  }
  SECTION("Reverberation after the arrival leaves the lead as silent") {
    EnergyResponse er(0.5, 1e-3);
    for (size_t k = size_t(delay * 1e3); k < er.binCount(); ++k)
      er.bins()[k] = Bands(1e-4f * std::exp(-13.8f * float(k) * 1e-3f));
    d.intensity = Bands(1e-3f);
    synth.synthesize(er, d, ir.data());
    const size_t zeros = leadingZeros(ir);
    INFO("leading zeros " << zeros << " (" << 1e3 * double(zeros) / fs << " ms)");
    CHECK(zeros >= size_t(0.020 * fs));
    CHECK(zeros < onset);
  }
}

TEST_CASE("cutLeadingResidue zeroes exactly the leading samples within -80 dB, on all channels",
          "[ir]") {
  // Two channels 40 dB apart: 1000 leading samples of v (ringing), a unit pulse at the onset
  // (sample 1000). The reference is both channels' energy up to 1 ms (48 samples) after it;
  // the cut takes the largest k leading samples whose summed energy k e stays within 1e-8 of
  // it, in both channels alike.
  const int fs = 48000;
  const size_t length = 4000, onset = 1000;
  const float v = 1.1e-5f, weak = 0.01f;
  std::vector<float> a(length, 0.f), b(length, 0.f);
  for (size_t n = 0; n < onset; ++n) a[n] = v, b[n] = weak * v;
  a[onset] = 1.f, b[onset] = weak;
  a[onset + 100] = 0.5f;  // after onset + 1 ms: not in the reference, never cut
  const double e = double(v) * v + double(weak * v) * double(weak * v);
  const double reference = double(onset) * e + 1.0 + double(weak) * double(weak);
  const size_t k = size_t(std::floor(kLeadingResidueEnergy * reference / e));
  REQUIRE(k > 10);
  REQUIRE(k < onset);
  float* const channels[] = {a.data(), b.data()};
  CHECK(cutLeadingResidue(channels, length, onset, fs) == k);
  for (size_t n = 0; n < k; ++n) REQUIRE((a[n] == 0.f && b[n] == 0.f));
  CHECK(a[k] == v);
  CHECK(b[k] == weak * v);
  CHECK(a[onset] == 1.f);
  CHECK(a[onset + 100] == 0.5f);
  SECTION("Silence stays silence; an onset beyond the IR cuts within it") {
    std::vector<float> zero(length, 0.f);
    float* const silent[] = {zero.data()};
    cutLeadingResidue(silent, length, length + 10, fs);
    for (float x : zero) REQUIRE(x == 0.f);
    std::vector<float> ramp(length, 1.f);
    float* const loud[] = {ramp.data()};
    CHECK(cutLeadingResidue(loud, length, length + 10, fs) == 0);
    CHECK(ramp.back() == 1.f);
  }
}

// IrSynthesizer::Build::kFirstIr (a live session's first IR) leaves the band sequences'
// levelling and the window leveller to complete(). Oracle: a synthesiser built complete with the
// same seed; the second of each pair shares the first's workspace, as hybrid rendering's do.
TEST_CASE("A first-IR build, completed, synthesises the complete build's IR bit for bit", "[ir]") {
  const int fs = 48000;
  const EnergyResponse er = exponentialDecay(8);
  DirectSound direct;
  direct.visible = true;
  direct.delaySeconds = 0.006f;
  direct.intensity = Bands(2e-3f);
  const auto pair = [&](IrSynthesizer::Build build) {
    std::vector<std::unique_ptr<IrSynthesizer>> s;
    s.push_back(std::make_unique<IrSynthesizer>(fs, 1.0, 210.0, 343.0, 7, nullptr, build));
    s.push_back(std::make_unique<IrSynthesizer>(fs, 1.0, 210.0, 343.0, 8, s[0].get(), build));
    return s;
  };
  const auto irs = [&](std::vector<std::unique_ptr<IrSynthesizer>>& s) {
    std::vector<std::vector<float>> out;
    for (auto& synth : s) {
      out.emplace_back(synth->lengthSamples());
      synth->synthesize(er, direct, out.back().data());
    }
    return out;
  };
  auto complete = pair(IrSynthesizer::Build::kComplete);
  auto quick = pair(IrSynthesizer::Build::kFirstIr);
  CHECK(complete[1]->completed());
  CHECK_FALSE(quick[1]->completed());
  const auto want = irs(complete);
  const auto first = irs(quick);
  CHECK(first[0] != want[0]);  // unlevelled: another realisation
  CHECK(first[1] != want[1]);
  quick[0]->complete();
  quick[1]->complete(quick[0].get());
  CHECK(quick[1]->completed());
  CHECK(irs(quick) == want);
}

// The first IR is unlevelled but unbiased: the envelope sets each band's energy in expectation
// over the pulses' signs whether or not the realisation is levelled. Same oracle and tolerance
// as the complete build's case above (ISO 3382-1 octave filters; mean of 10 sequences within 3
// standard errors plus 0.1 dB).
TEST_CASE("A first-IR build's IR has the energy response's band energies", "[ir][statistics]") {
  const int fs = 48000;
  Bands t60;
  const EnergyResponse er = bandDependentDecay(t60);
  const Bands want = er.total();
  std::array<std::vector<double>, kNumBands> ratios;
  for (int seed = 1; seed <= 10; ++seed) {
    IrSynthesizer synth(fs, 1.5, 210.0, 343.0, uint64_t(seed), nullptr,
                        IrSynthesizer::Build::kFirstIr);
    const Bands got = analysisBandEnergies(synthesizeWithoutDirect(synth, er), fs);
    for (int b = 0; b < kNumBands; ++b) ratios[size_t(b)].push_back(got[b] / want[b]);
  }
  for (int b = 0; b < kNumBands; ++b) {
    const auto [m, se] = test::meanAndStandardError(ratios[size_t(b)]);
    INFO("band " << b << ": first IR / energy response = " << db(m) << " dB +- " << se);
    CHECK(std::abs(m - 1.0) < 3 * se + 0.023);  // 0.1 dB
  }
}
