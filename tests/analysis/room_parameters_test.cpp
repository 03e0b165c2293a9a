// Tests for audio/room_parameters against constructed truths: exponentially decaying noise of
// known T60, band-wise decays, an ideal impulse, energy envelopes whose Schroeder curve is known
// in closed form, and decays over a stationary noise floor (analysis/noise_floor.h).
#include "analysis/room_parameters.h"

#include <fftw3.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "analysis/noise_floor.h"

using dpc::bandCentreExactHz;
using dpc::kNumBands;
using dpc::audio::analyzeEnergyDecay;
using dpc::audio::analyzeImpulseResponse;
using dpc::audio::ImpulseResponseAnalysis;
using dpc::audio::RoomParameters;

namespace {

constexpr int kFs = 48000;

// Amplitude envelope of a decay with reverberation time t60: energy falls 60 dB in t60 seconds.
double envelope(double t, double t60) {
  return std::pow(10.0, -3.0 * t / t60);
}

// Gaussian white noise times the decay envelope: expected energy decays exactly with t60 in
// every band. Length `seconds`, fixed seed.
std::vector<float> decayingNoise(double t60, double seconds, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss;
  std::vector<float> p(size_t(seconds * kFs));
  for (size_t i = 0; i < p.size(); ++i) p[i] = float(gauss(rng) * envelope(double(i) / kFs, t60));
  return p;
}

// Noise band-limited to [f1, f2) by an ideal (FFT brick-wall) filter — a construction
// independent of the analyser's Butterworth filters — times the decay envelope for t60.
std::vector<float> decayingBandNoise(double f1, double f2, double t60, size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss;
  std::vector<float> x(n);
  for (float& v : x) v = gauss(rng);
  const size_t bins = n / 2 + 1;
  fftwf_complex* spectrum = fftwf_alloc_complex(bins);
  fftwf_plan forward = fftwf_plan_dft_r2c_1d(int(n), x.data(), spectrum, FFTW_ESTIMATE);
  fftwf_plan backward = fftwf_plan_dft_c2r_1d(int(n), spectrum, x.data(), FFTW_ESTIMATE);
  fftwf_execute(forward);
  for (size_t k = 0; k < bins; ++k) {
    const double f = double(k) * kFs / double(n);
    if (f < f1 || f >= f2) spectrum[k][0] = spectrum[k][1] = 0.f;
  }
  fftwf_execute(backward);
  fftwf_destroy_plan(forward);
  fftwf_destroy_plan(backward);
  fftwf_free(spectrum);
  for (size_t i = 0; i < n; ++i) x[i] *= float(envelope(double(i) / kFs, t60) / double(n));
  return x;
}

// Octave bandwidth (Hz) of band b, for the statistical spread of decay-time estimates.
double bandwidthHz(int b) {
  return bandCentreExactHz(b) / std::sqrt(2.0);
}

// Tolerance on the mean relative error of a decay time over `seeds` independent decays.
// The Schroeder curve of band-limited noise fluctuates: the relative standard deviation of one
// estimate is about c / sqrt(B * T) (B bandwidth in Hz, T the decay time), the form of
// ISO 3382-2:2008's uncertainty estimate; measured with this analyser over 40 seeds:
// c = 0.8 (T20), 0.5 (T30), 1.6 (EDT), with broadband noise (B ~ 24 kHz) <= 2 %. We allow
// 4 standard deviations of the mean plus 3 % for the octave filter's own ringing (which
// lengthens short decays: measured +5 % T30, +19 % EDT at 63 Hz, T = 0.5 s).
double tolerance(double c, double bandwidth, double t60, int seeds) {
  return 0.03 + 4.0 * c / std::sqrt(double(seeds) * bandwidth * t60);
}

bool allNaNTimes(const RoomParameters& r) {
  return std::isnan(r.t20) && std::isnan(r.t30) && std::isnan(r.edt);
}

// Least-squares decay time of the analytic curve levelDb(k*dt) over points in [lo, hi] dB —
// the textbook regression, computed here independently of the analyser.
template <class Level>
double regressionT(Level levelDb, size_t n, double dt, double hi, double lo) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0, m = 0;
  for (size_t k = 0; k < n; ++k) {
    const double l = levelDb(k), x = double(k) * dt;
    if (l > hi || l < lo) continue;
    sx += x, sy += l, sxx += x * x, sxy += x * l, m += 1;
  }
  return -60.0 / ((m * sxy - sx * sy) / (m * sxx - sx * sx));
}

}  // namespace

TEST_CASE("decaying noise: T20, T30, EDT recover T60 in every band and broadband") {
  const double t60 = GENERATE(0.5, 1.2, 2.0);
  constexpr int kSeeds = 16;
  std::array<double, kNumBands + 1> meanT20{}, meanT30{}, meanEdt{};
  for (int s = 0; s < kSeeds; ++s) {
    // 1.3 * T60 long: the envelope ends at -78 dB, far below the -45 dB T30 needs.
    const std::vector<float> p = decayingNoise(t60, 1.3 * t60, 1000u + unsigned(s));
    const ImpulseResponseAnalysis a = analyzeImpulseResponse(p.data(), p.size(), kFs);
    // A single broadband estimate is already good: the noise has ~24 kHz of bandwidth.
    CHECK(a.broadband.t30 == Approx(t60).epsilon(0.02));
    CHECK(a.broadband.t20 == Approx(t60).epsilon(0.02));
    CHECK(a.broadband.edt == Approx(t60).epsilon(0.05));
    for (int b = 0; b <= kNumBands; ++b) {
      const RoomParameters& r = b < kNumBands ? a.bands[size_t(b)] : a.broadband;
      meanT20[size_t(b)] += r.t20 / t60 / kSeeds;
      meanT30[size_t(b)] += r.t30 / t60 / kSeeds;
      meanEdt[size_t(b)] += r.edt / t60 / kSeeds;
    }
  }
  for (int b = 0; b <= kNumBands; ++b) {
    const double bw = b < kNumBands ? bandwidthHz(b) : 24000.0;
    INFO("T60 " << t60 << " s, band " << (b < kNumBands ? bandCentreExactHz(b) : 0.0) << " Hz");
    CHECK(std::abs(meanT20[size_t(b)] - 1) < tolerance(0.8, bw, t60, kSeeds));
    CHECK(std::abs(meanT30[size_t(b)] - 1) < tolerance(0.5, bw, t60, kSeeds));
    // EDT's 10 dB range is short: at B * T60 < 32 (only 63 Hz with T60 = 0.5 s) the band
    // filter's delay and ringing (~10 ms) are a large part of it and EDT reads ~20-40 % long.
    // That is the filter's limit (ISO 3382-1 asks B * T > 16 for T20/T30), not checked here.
    if (bw * t60 >= 32) CHECK(std::abs(meanEdt[size_t(b)] - 1) < tolerance(1.6, bw, t60, kSeeds));
  }
}

TEST_CASE("decaying noise: C50, C80, D50 match the exponential decay's closed form") {
  // Expected energy e(t) ∝ exp(-a t), a = 6 ln(10) / T60, from t = 0:
  // E(0, T) / E(T, ∞) = exp(a T) - 1;  D50 = 1 - exp(-a 0.05).
  const double t60 = 1.2, a = 6.0 * std::log(10.0) / t60;
  const std::vector<float> p = decayingNoise(t60, 1.3 * t60, 7);
  const RoomParameters r = analyzeImpulseResponse(p.data(), p.size(), kFs).broadband;
  // The early energy is a sum of ~2400 (50 ms) squared Gaussians: ~3 % spread -> 0.15 dB.
  CHECK(r.c50 == Approx(10 * std::log10(std::exp(a * 0.05) - 1)).margin(0.25));
  CHECK(r.c80 == Approx(10 * std::log10(std::exp(a * 0.08) - 1)).margin(0.25));
  CHECK(r.d50 == Approx(1 - std::exp(-a * 0.05)).epsilon(0.06));
}

TEST_CASE("band-dependent decays: each octave band's T30 is recovered") {
  // Each band's noise is built separately (ideal band-limited to the band's edges) with its own
  // T60, then the bands are summed. Neighbouring bands leak through the Butterworth skirts, so
  // T60 changes smoothly from band to band (about 15 % per octave, as in real rooms). Measured
  // leakage bias over 16 seeds: <= +3 % (63 Hz), +2 % (8 kHz); with 33 % steps (0.8 s next to
  // 0.6 s) the 8 kHz band reads +6 %, which is the octave filters' overlap, not an analysis error.
  const std::array<double, kNumBands> t60 = {2.0, 1.75, 1.5, 1.3, 1.15, 1.0, 0.87, 0.75};
  constexpr int kSeeds = 8;
  const size_t n = size_t(2.6 * kFs);
  std::array<double, kNumBands> meanT30{};
  for (int s = 0; s < kSeeds; ++s) {
    std::vector<float> sum(n, 0.f);
    for (int b = 0; b < kNumBands; ++b) {
      const double fc = bandCentreExactHz(b);
      const std::vector<float> x = decayingBandNoise(fc / std::sqrt(2.0), fc * std::sqrt(2.0),
                                                     t60[size_t(b)], n, 100u * unsigned(s) + b);
      for (size_t i = 0; i < n; ++i) sum[i] += x[i];
    }
    const ImpulseResponseAnalysis a = analyzeImpulseResponse(sum.data(), n, kFs);
    for (int b = 0; b < kNumBands; ++b) meanT30[size_t(b)] += a.bands[size_t(b)].t30 / kSeeds;
  }
  for (int b = 0; b < kNumBands; ++b) {
    INFO("band " << bandCentreExactHz(b) << " Hz, T60 " << t60[size_t(b)]);
    CHECK(meanT30[size_t(b)] ==
          Approx(t60[size_t(b)]).epsilon(tolerance(0.5, bandwidthHz(b), t60[size_t(b)], kSeeds)));
  }
}

TEST_CASE("an ideal single impulse: all energy is early, no decay to fit") {
  // Decision: C = 10 log10(early / late) with late = 0 is +infinity (not NaN: the ratio is
  // defined and unbounded), D50 = 1, and reverberation times are NaN (the curve drops from 0 dB
  // straight to -inf: no point inside any regression range).
  std::vector<float> p(kFs / 2, 0.f);
  p[480] = 0.8f;  // arrives after 10 ms
  const ImpulseResponseAnalysis a = analyzeImpulseResponse(p.data(), p.size(), kFs);
  CHECK(a.broadband.c50 == std::numeric_limits<double>::infinity());
  CHECK(a.broadband.c80 == std::numeric_limits<double>::infinity());
  CHECK(a.broadband.d50 == 1.0);
  CHECK(allNaNTimes(a.broadband));
  // Band-filtered, the impulse rings briefly; at 250 Hz and above the ringing is over long
  // before 50 ms, relative to the broadband onset (octave Butterworth: envelope time constant
  // ~ 1 / (pi * B * 0.5) <= 8 ms at 250 Hz, so > 6 time constants fit into 50 ms).
  for (int b = 2; b < kNumBands; ++b) {
    INFO("band " << bandCentreExactHz(b) << " Hz");
    CHECK(a.bands[size_t(b)].d50 > 0.999);
    CHECK(a.bands[size_t(b)].c80 > 30.0);
  }
}

TEST_CASE("silence and empty input give NaN, never a number") {
  std::vector<float> zeros(1000, 0.f);
  const ImpulseResponseAnalysis a = analyzeImpulseResponse(zeros.data(), zeros.size(), kFs);
  CHECK(allNaNTimes(a.broadband));
  CHECK(std::isnan(a.broadband.c80));
  CHECK(std::isnan(a.broadband.d50));
  CHECK(allNaNTimes(analyzeEnergyDecay(nullptr, 0, 0.01)));
}

TEST_CASE("octave bands above Nyquist are NaN, not aliased") {
  // At 22.05 kHz the 8 kHz band's upper edge (11.3 kHz) is above Nyquist (11.025 kHz).
  std::mt19937 rng(3);
  std::normal_distribution<double> gauss;
  const int fs = 22050;
  std::vector<float> p(size_t(1.0 * fs));
  for (size_t i = 0; i < p.size(); ++i) p[i] = float(gauss(rng) * envelope(double(i) / fs, 0.7));
  const ImpulseResponseAnalysis a = analyzeImpulseResponse(p.data(), p.size(), fs);
  CHECK(allNaNTimes(a.bands[7]));
  CHECK(std::isnan(a.bands[7].c80));
  CHECK(a.bands[6].t30 == Approx(0.7).epsilon(0.1));  // 4 kHz (edge 5.7 kHz) still works
}

TEST_CASE("band energy bins: the band analysis' energy, binned from the broadband onset") {
  // Decaying noise after 5 ms of silence at 22.05 kHz: 1 ms asks for 22.05 samples per bin,
  // rounded to 22; the 8 kHz band lies above Nyquist there.
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss;
  const int fs = 22050;
  const size_t lead = size_t(0.005 * fs);
  std::vector<float> p(lead + size_t(1.2 * fs), 0.f);
  for (size_t i = lead; i < p.size(); ++i)
    p[i] = float(gauss(rng) * envelope(double(i - lead) / fs, 0.7));
  const ImpulseResponseAnalysis a = analyzeImpulseResponse(p.data(), p.size(), fs);
  const dpc::audio::BandEnergyBins bins = dpc::audio::bandEnergyBins(p.data(), p.size(), fs, 1e-3);
  CHECK(bins.binSeconds == Approx(22.0 / fs).epsilon(1e-12));
  // The onset is the first sample within 20 dB of the peak: after the silence, and (Gaussian
  // noise at the decay's start reaches that level within a few samples) within 1 ms of it.
  CHECK(bins.onsetSeconds >= double(lead) / fs);
  CHECK(bins.onsetSeconds < double(lead) / fs + 1e-3);
  CHECK(bins.energy[7].empty());
  for (int b = 0; b < 7; ++b) {
    INFO("band " << bandCentreExactHz(b) << " Hz");
    const std::vector<double>& e = bins.energy[size_t(b)];
    REQUIRE(e.size() == (p.size() - size_t(std::lround(bins.onsetSeconds * fs)) + 21) / 22);
    // The same filtered samples from the same onset: the totals agree to rounding.
    double total = 0.0;
    for (double v : e) total += v;
    CHECK(total == Approx(a.bands[size_t(b)].energy).epsilon(1e-9));
    // The binned Schroeder curve is the per-sample one read at bin starts, so its T30 differs
    // only by the regression's points (22 samples apart instead of 1): within 1 %.
    const RoomParameters r = analyzeEnergyDecay(e.data(), e.size(), bins.binSeconds);
    CHECK(r.t30 == Approx(a.bands[size_t(b)].t30).epsilon(0.01));
  }
  // Silence and invalid bins: NaN times, no bins.
  const std::vector<float> zeros(1000, 0.f);
  const auto silent = dpc::audio::bandEnergyBins(zeros.data(), zeros.size(), fs, 1e-3);
  CHECK(std::isnan(silent.onsetSeconds));
  CHECK(silent.energy[3].empty());
  const auto invalid = dpc::audio::bandEnergyBins(p.data(), p.size(), fs, 0.0);
  CHECK(std::isnan(invalid.binSeconds));
  CHECK(invalid.energy[3].empty());
}

namespace {

// Bins whose backward sum is exactly S(t) = 10^(L(t)/10), L two straight lines in dB: fast
// (`fastDbPerS`) down to `kneeDb`, then `slowDbPerS`. Bin k holds S(k dt) - S((k+1) dt); the
// last bin holds the rest. `lead` empty bins (travel time) come first.
struct TwoSlope {
  double fastDbPerS, kneeDb, slowDbPerS;
  double levelDb(double t) const {
    const double tKnee = -kneeDb / fastDbPerS;
    return t <= tKnee ? -fastDbPerS * t : kneeDb - slowDbPerS * (t - tKnee);
  }
  double tail(double t) const { return std::pow(10.0, levelDb(t) / 10); }
  std::vector<double> bins(size_t n, double dt, size_t lead) const {
    std::vector<double> e(lead + n, 0.0);
    for (size_t k = 0; k < n; ++k)
      e[lead + k] = tail(double(k) * dt) - (k + 1 < n ? tail(double(k + 1) * dt) : 0.0);
    return e;
  }
};

}  // namespace

TEST_CASE("two-slope energy envelope: exact closed-form values through analyzeEnergyDecay") {
  const double dt = 0.001;  // 1 ms bins
  const size_t n = 2500;    // 2.5 s: the curve ends far below -45 dB
  SECTION("knee at -5 dB: T20 and T30 on the late slope, EDT straddles") {
    // 200 dB/s (T = 0.3 s) to -5 dB at 25 ms, then 30 dB/s (T = 2 s).
    const TwoSlope d{200.0, -5.0, 30.0};
    const std::vector<double> e = d.bins(n, dt, 7);
    const RoomParameters r = analyzeEnergyDecay(e.data(), e.size(), dt);
    CHECK(r.t20 == Approx(2.0).epsilon(1e-9));
    CHECK(r.t30 == Approx(2.0).epsilon(1e-9));
    // EDT's range (0..-10 dB) straddles the knee: least squares through the analytic points.
    const double edt =
        regressionT([&](size_t k) { return d.levelDb(double(k) * dt); }, n, dt, 0.0, -10.0);
    CHECK(r.edt == Approx(edt).epsilon(1e-9));
    CHECK(r.edt > 0.3);
    CHECK(r.edt < 2.0);
    // Energy ratios: early = 1 - S(T), late = S(T) (50 and 80 ms are whole bins).
    const double s50 = d.tail(0.05), s80 = d.tail(0.08);
    CHECK(r.c50 == Approx(10 * std::log10((1 - s50) / s50)).epsilon(1e-9));
    CHECK(r.c80 == Approx(10 * std::log10((1 - s80) / s80)).epsilon(1e-9));
    CHECK(r.d50 == Approx(1 - s50).epsilon(1e-9));
    // The empty lead bins (travel time) change nothing: the onset is the first non-zero bin.
    const std::vector<double> noLead = d.bins(n, dt, 0);
    const RoomParameters r0 = analyzeEnergyDecay(noLead.data(), noLead.size(), dt);
    CHECK(r0.edt == Approx(r.edt).epsilon(1e-12));
    CHECK(r0.c80 == Approx(r.c80).epsilon(1e-12));
  }
  SECTION("knee at -20 dB: EDT on the early slope, T20 and T30 straddle differently") {
    // 60 dB/s (T = 1 s) to -20 dB at 0.333 s, then 40 dB/s (T = 1.5 s). Any error in the
    // -5/-25/-35 dB range limits moves T20 or T30 away from these values.
    const TwoSlope d{60.0, -20.0, 40.0};
    const std::vector<double> e = d.bins(n, dt, 3);
    const RoomParameters r = analyzeEnergyDecay(e.data(), e.size(), dt);
    auto level = [&](size_t k) { return d.levelDb(double(k) * dt); };
    CHECK(r.edt == Approx(1.0).epsilon(1e-9));
    CHECK(r.t20 == Approx(regressionT(level, n, dt, -5.0, -25.0)).epsilon(1e-9));
    CHECK(r.t30 == Approx(regressionT(level, n, dt, -5.0, -35.0)).epsilon(1e-9));
    CHECK(r.t20 < r.t30);  // more of the slower slope in the T30 range
    CHECK(r.t30 < 1.5);
  }
}

TEST_CASE("a bin that straddles 50 ms is split in proportion to time") {
  // Constant energy per bin of 30 ms: 50 ms = 1 bin + 2/3 of the next.
  const std::vector<double> e(200, 1.0);
  const RoomParameters r = analyzeEnergyDecay(e.data(), e.size(), 0.030);
  CHECK(r.d50 == Approx((5.0 / 3.0) / 200.0).epsilon(1e-12));
  CHECK(r.c80 == Approx(10 * std::log10((8.0 / 3.0) / (200.0 - 8.0 / 3.0))).epsilon(1e-12));
}

TEST_CASE("an onset inside its bin: C50, C80 and D50 split where the per-sample record does") {
  // Reference: a per-sample energy record (48 kHz) with the direct sound at 2.4 ms and an
  // exponential decay (T = 0.8 s) from 3.1 ms, analysed from its own onset sample. The same
  // record in 1 ms bins, told the onset, must read the same: the only difference left is the
  // decay's slope within the split bin (1.7 % over 1 ms, so under 0.01 % of the early energy:
  // tolerance 0.002 dB). From the bin's start instead (no onset given) its 80 ms split lands
  // 0.4 ms early, moving C80 by about 0.03 dB, which the check must see.
  const double t0 = 0.0024, t60 = 0.8;
  const size_t samples = size_t(1.5 * kFs), perBin = kFs / 1000;
  std::vector<double> fine(samples, 0.0), bins(samples / perBin, 0.0);
  const size_t direct = size_t(std::lround(t0 * kFs));
  fine[direct] = 0.05;
  for (size_t i = size_t(0.0031 * kFs); i < samples; ++i)
    fine[i] = std::pow(10.0, -6.0 * double(i) / kFs / t60) / kFs;
  for (size_t i = 0; i < samples; ++i) bins[i / perBin] += fine[i];
  const RoomParameters ref = analyzeEnergyDecay(fine.data(), fine.size(), 1.0 / kFs);
  const RoomParameters told = analyzeEnergyDecay(bins.data(), bins.size(), 1e-3, t0);
  const RoomParameters start = analyzeEnergyDecay(bins.data(), bins.size(), 1e-3);
  CHECK(told.c80 == Approx(ref.c80).margin(0.002));
  CHECK(told.c50 == Approx(ref.c50).margin(0.002));
  CHECK(told.d50 == Approx(ref.d50).margin(5e-5));
  CHECK(std::abs(start.c80 - ref.c80) > 0.02);
  // An onset outside the first non-empty bin is ignored (the bin's start is used).
  const RoomParameters outside = analyzeEnergyDecay(bins.data(), bins.size(), 1e-3, 0.0034);
  CHECK(outside.c80 == Approx(start.c80).epsilon(1e-12));
}

TEST_CASE("a decay recorded too briefly for T30 gives NaN for T30 but a value for T20") {
  // Single exponential, T = 1 s (60 dB/s), 1 ms bins, record cut at `seconds`. The backward
  // integral of a truncated decay plunges at the end of the record; ranges must end >= 10 dB
  // above the curve's level at 90 % of the record (the analyser's floor rule).
  auto analyse = [](double seconds) {
    const double dt = 0.001;
    std::vector<double> e(size_t(std::lround(seconds / dt)));
    for (size_t k = 0; k < e.size(); ++k) e[k] = std::pow(10.0, -6.0 * double(k) * dt);
    return analyzeEnergyDecay(e.data(), e.size(), dt);
  };
  // 0.7 s: envelope ends at -42 dB; the curve at 90 % is -39.9 dB -> floor + 10 = -29.9 dB:
  // T20 (-25 dB) allowed, T30 (-35 dB) not.
  const RoomParameters brief = analyse(0.7);
  CHECK(std::isnan(brief.t30));
  // Truncation lowers the curve by 10 log10(1 - 10^-4.2 / 10^-2.5) = -0.09 dB at -25 dB.
  CHECK(brief.t20 == Approx(1.0).epsilon(0.03));
  CHECK(brief.edt == Approx(1.0).epsilon(0.01));
  // 0.3 s (envelope to -18 dB): not even T20.
  const RoomParameters tooBrief = analyse(0.3);
  CHECK(std::isnan(tooBrief.t20));
  CHECK(std::isnan(tooBrief.t30));
  // Control: 1.2 s (-72 dB) gives all three.
  const RoomParameters full = analyse(1.2);
  CHECK(full.t30 == Approx(1.0).epsilon(0.005));
  CHECK(full.t20 == Approx(1.0).epsilon(0.005));
  CHECK(full.edt == Approx(1.0).epsilon(0.005));
}

TEST_CASE("octave filters: -3 dB at the band edges, Butterworth attenuation an octave away") {
  // IR = unit impulse at t = 0 (early) + a long tapered tone at frequency f starting at 0.2 s
  // (late). The early part is the same for every f, so the band's C50 moves by exactly the
  // change of the filter's power gain |H(f)|^2 between two tones. Truth: the analog 6th-order
  // Butterworth band-pass, |H|^2 = 1 / (1 + Omega^6), Omega = (w^2 - w0^2) / (w (w2 - w1)),
  // evaluated at the prewarped frequencies w = 2 fs tan(pi f / fs) (the bilinear transform
  // maps it exactly), w1, w2 the prewarped edges fc 2^(-1/2), fc 2^(1/2), w0 = sqrt(w1 w2).
  const double pi = 3.14159265358979323846;
  auto warp = [&](double f) { return 2.0 * kFs * std::tan(pi * f / kFs); };
  auto gainDb = [&](double fc, double f) {
    const double w1 = warp(fc / std::sqrt(2.0)), w2 = warp(fc * std::sqrt(2.0));
    const double w = warp(f), w0sq = w1 * w2;
    const double omega = (w * w - w0sq) / (w * (w2 - w1));
    return -10.0 * std::log10(1.0 + std::pow(omega, 6));
  };
  auto c50WithTone = [&](int band, double f) {
    const double start = 0.2, length = 3.0, taper = 1.0;  // narrow, low sidelobes
    std::vector<float> p(size_t((start + length + 0.1) * kFs), 0.f);
    p[0] = 1.f;
    for (size_t i = 0; i < size_t(length * kFs); ++i) {
      const double t = double(i) / kFs;
      const double fade = std::min({1.0, t / taper, (length - t) / taper});
      const double w = 0.5 - 0.5 * std::cos(pi * fade);  // raised-cosine taper
      p[size_t(start * kFs) + i] = float(0.5 * w * std::sin(2 * pi * f * t));
    }
    return analyzeImpulseResponse(p.data(), p.size(), kFs).bands[size_t(band)].c50;
  };
  for (int b : {0, 4, 7}) {
    const double fc = bandCentreExactHz(b);
    const double atCentre = c50WithTone(b, fc);
    for (double f : {fc * std::sqrt(2.0), fc / std::sqrt(2.0), 2.0 * fc, 0.5 * fc}) {
      INFO("band " << fc << " Hz, tone " << f << " Hz");
      // C50 rises by the attenuation of the late tone relative to the centre.
      const double expected = gainDb(fc, fc) - gainDb(fc, f);
      CHECK(c50WithTone(b, f) - atCentre == Approx(expected).margin(0.05));
    }
    // Sanity of the truth itself: the edges are 3.01 dB down, an octave away >= 19 dB.
    CHECK(gainDb(fc, fc * std::sqrt(2.0)) == Approx(-3.0103).margin(1e-3));
    CHECK(gainDb(fc, 2.0 * fc) < -19.0);
  }
}

TEST_CASE("onset: quiet pre-roll before the direct sound is excluded (20 dB below the peak)") {
  // The same decay, once alone and once after 20 ms of noise 40 dB below its starting RMS
  // (~53 dB below its peak) and 5 ms of silence. The onset rule puts t0 at the decay's first
  // sample within 20 dB of the peak in both, so every broadband parameter must agree.
  const std::vector<float> decay = decayingNoise(1.0, 1.3, 11);
  std::mt19937 rng(12);
  std::normal_distribution<double> gauss;
  std::vector<float> withPreRoll(size_t(0.025 * kFs), 0.f);
  for (size_t i = 0; i < size_t(0.020 * kFs); ++i) withPreRoll[i] = float(0.01 * gauss(rng));
  withPreRoll.insert(withPreRoll.end(), decay.begin(), decay.end());
  const RoomParameters a = analyzeImpulseResponse(decay.data(), decay.size(), kFs).broadband;
  const RoomParameters b =
      analyzeImpulseResponse(withPreRoll.data(), withPreRoll.size(), kFs).broadband;
  CHECK(b.c50 == Approx(a.c50).epsilon(1e-9));
  CHECK(b.c80 == Approx(a.c80).epsilon(1e-9));
  CHECK(b.d50 == Approx(a.d50).epsilon(1e-9));
  CHECK(b.edt == Approx(a.edt).epsilon(1e-9));
  CHECK(b.t30 == Approx(a.t30).epsilon(1e-9));
}

TEST_CASE("a record that ends before 50 or 80 ms has no C or D there: NaN, not +inf") {
  // Constant energy in 1 ms bins: a late part exists in the room but was never recorded. A
  // 40 ms record cannot give C50, C80 or D50; a 60 ms record gives C50 and D50 (closed form:
  // 50 of 60 bins early) but not C80. An impulse followed by recorded silence stays +inf.
  const std::vector<double> e40(40, 1.0), e60(60, 1.0);
  const RoomParameters short40 = analyzeEnergyDecay(e40.data(), e40.size(), 0.001);
  CHECK(std::isnan(short40.c50));
  CHECK(std::isnan(short40.c80));
  CHECK(std::isnan(short40.d50));
  const RoomParameters short60 = analyzeEnergyDecay(e60.data(), e60.size(), 0.001);
  CHECK(short60.c50 == Approx(10 * std::log10(50.0 / 10.0)).epsilon(1e-9));
  CHECK(short60.d50 == Approx(50.0 / 60.0).epsilon(1e-9));
  CHECK(std::isnan(short60.c80));
  std::vector<double> impulse(500, 0.0);
  impulse[0] = 1.0;
  const RoomParameters single = analyzeEnergyDecay(impulse.data(), impulse.size(), 0.001);
  CHECK(std::isinf(single.c80));
  CHECK(single.c80 > 0);
}

namespace {

// Decaying noise (decayingNoise, 48 kHz) plus stationary Gaussian noise `belowDb` below the
// decay's initial level (its expected p² at t = 0), each seeded.
std::vector<float> decayOverNoise(double t60, double seconds, double belowDb, unsigned seed) {
  std::vector<float> p = decayingNoise(t60, seconds, seed);
  std::mt19937 rng(seed + 7919u);
  std::normal_distribution<double> gauss;
  const double sigma = std::pow(10.0, -belowDb / 20.0);
  for (float& v : p) v = float(double(v) + sigma * gauss(rng));
  return p;
}

// The decay time Lundeby's method reads from the expected energy exp(-k t) + N (k = 6 ln 10 /
// t60, N = 10^(-belowDb / 10)): the backward integral stopped at the true crossing tc
// (exp(-k tc) = N) plus the exact correction exp(-k tc) / k is S(t) = exp(-k t) / k +
// N (tc - t), regressed over [lo, hi] dB at 48 kHz. The noise left before tc lengthens the decay
// (T = 1 s: T20 +1.6 % at 41.6 dB, T30 +1.2 % at 50 dB): the method's own bias, not the analyser's.
double lundebyExpected(double t60, double belowDb, double hi, double lo) {
  const double k = 6.0 * std::log(10.0) / t60, noise = std::pow(10.0, -belowDb / 10.0);
  const double tc = belowDb / 60.0 * t60;
  const double s0 = 1.0 / k + noise * tc;
  auto level = [&](size_t i) {
    const double t = double(i) / kFs;
    return 10.0 * std::log10((std::exp(-k * t) / k + noise * (tc - t)) / s0);
  };
  return regressionT(level, size_t(tc * kFs), 1.0 / kFs, hi, lo);
}

std::vector<double> squared(const std::vector<float>& p) {
  std::vector<double> e(p.size());
  for (size_t i = 0; i < p.size(); ++i) e[i] = double(p[i]) * double(p[i]);
  return e;
}

}  // namespace

TEST_CASE("a stationary noise floor: Lundeby's truncation and correction recover T20, T30, EDT") {
  // 3 s records of an exponential decay over stationary noise. Uncompensated, the Schroeder
  // curve reads T = 1 s over a floor 41.6 dB down as T20 1.24 s, and has no T30 over a floor
  // 50 dB down. The reference is lundebyExpected (the method's value for the expected energy,
  // at most +5 % above T60 here). Tolerances per single broadband estimate: 4 standard
  // deviations measured over 16 seeds (0.8 % T20, 0.4 % T30, 1.7 % EDT, within 0.4 % of the
  // reference in the mean), rounded up: 3.5 %, 2 %, 7 %.
  const double t60 = GENERATE(1.0, 0.5);
  const double belowDb = GENERATE(35.0, 41.6, 50.0, 60.0);
  for (unsigned seed = 0; seed < 4; ++seed) {
    const std::vector<float> p = decayOverNoise(t60, 3.0, belowDb, 200u + seed);
    const RoomParameters r = analyzeImpulseResponse(p.data(), p.size(), kFs).broadband;
    INFO("T60 " << t60 << " s, noise " << belowDb << " dB down, seed " << seed);
    INFO("T20 " << r.t20 << ", T30 " << r.t30 << ", EDT " << r.edt);
    // The floor is found at about -belowDb on the decay curve: T30 needs 45 dB below the
    // start, T20 35 dB (at 35 dB it may go either way), EDT 20 dB.
    if (belowDb >= 41.6) REQUIRE(std::isfinite(r.t20));
    if (std::isfinite(r.t20))
      CHECK(r.t20 == Approx(lundebyExpected(t60, belowDb, -5, -25)).epsilon(0.035));
    if (belowDb >= 50.0) {
      REQUIRE(std::isfinite(r.t30));
      CHECK(r.t30 == Approx(lundebyExpected(t60, belowDb, -5, -35)).epsilon(0.02));
    } else {
      CHECK(std::isnan(r.t30));
    }
    REQUIRE(std::isfinite(r.edt));
    CHECK(r.edt == Approx(lundebyExpected(t60, belowDb, 0, -10)).epsilon(0.07));
    CHECK(lundebyExpected(t60, belowDb, -5, -35) == Approx(t60).epsilon(0.05));
  }
}

TEST_CASE("the floor itself: found at the noise's level, the decay crossing it where it should") {
  // The noise region's mean lies within 0.5 dB of the noise synthesised (at most the decay's
  // own energy 10 dB below it: +0.4 dB), and the crossing within 5 % of belowDb / 60 * T60.
  const double t60 = GENERATE(1.0, 0.5);
  const double belowDb = GENERATE(41.6, 60.0);
  const std::vector<float> p = decayOverNoise(t60, 3.0, belowDb, 300u);
  const dpc::audio::NoiseFloor f = dpc::audio::findNoiseFloor(squared(p), 1.0 / kFs);
  INFO("T60 " << t60 << ", noise " << belowDb << " dB down: excess " << f.excessDb
              << " dB, crossing " << double(f.crossing) / kFs << " s, noise "
              << 10 * std::log10(f.noise) << " dB, slope " << f.decayDbPerSecond);
  REQUIRE(f.found);
  CHECK(10 * std::log10(f.noise) == Approx(-belowDb).margin(0.5));
  CHECK(double(f.crossing) / kFs == Approx(belowDb / 60.0 * t60).epsilon(0.05));
  CHECK(f.decayDbPerSecond == Approx(-60.0 / t60).epsilon(0.05));
}

TEST_CASE("an octave band over a noise floor: the band path is compensated too") {
  // T = 1 s over a floor 50 dB down: uncompensated, no band has a T30. The mean over the
  // seeds whose floor is found is held to `tolerance` (the band's statistical spread, see
  // above) around the method's expected value. A low band's few intervals leave its floor
  // unrecognised now and then (2 of 40 seeds at 125 Hz), and then its T30 is NaN, as
  // uncompensated: at least 6 of 8 must be found.
  constexpr int kSeeds = 8, kMinFound = 6;
  const double t60 = 1.0, belowDb = 50.0;
  for (int b : {1, 4}) {  // 125 Hz, 1 kHz
    double sumT20 = 0, sumT30 = 0;
    int found = 0;
    for (int s = 0; s < kSeeds; ++s) {
      const std::vector<float> p = decayOverNoise(t60, 3.0, belowDb, 400u + unsigned(s));
      const RoomParameters r = analyzeImpulseResponse(p.data(), p.size(), kFs).bands[size_t(b)];
      if (!std::isfinite(r.t30) || !std::isfinite(r.t20)) continue;
      sumT20 += r.t20, sumT30 += r.t30, ++found;
    }
    INFO("band " << bandCentreExactHz(b) << " Hz: " << found << " of " << kSeeds << " found, T20 "
                 << sumT20 / found << ", T30 " << sumT30 / found);
    REQUIRE(found >= kMinFound);
    const double bw = bandwidthHz(b);
    CHECK(sumT20 / found ==
          Approx(lundebyExpected(t60, belowDb, -5, -25)).epsilon(tolerance(0.8, bw, t60, found)));
    CHECK(sumT30 / found ==
          Approx(lundebyExpected(t60, belowDb, -5, -35)).epsilon(tolerance(0.5, bw, t60, found)));
  }
}

TEST_CASE("a decay only 15 dB above its noise gives no reverberation time") {
  // EDT alone needs the decay 20 dB above the noise (its range ends 10 dB above it).
  for (unsigned seed = 0; seed < 4; ++seed) {
    for (double t60 : {1.0, 0.5}) {
      const std::vector<float> p = decayOverNoise(t60, 3.0, 15.0, 500u + seed);
      const ImpulseResponseAnalysis a = analyzeImpulseResponse(p.data(), p.size(), kFs);
      INFO("T60 " << t60 << ", seed " << seed);
      CHECK(allNaNTimes(a.broadband));
      for (int b = 0; b < kNumBands; ++b) CHECK(allNaNTimes(a.bands[size_t(b)]));
    }
  }
}

TEST_CASE("a noise-free decay cut off while still running: no floor, the 90 % rule applies") {
  // dpc's own responses end at their length with the decay running. The tail then falls at the
  // decay's rate and lies on its extrapolation, so no floor is found and the 90 % rule (see
  // "a decay recorded too briefly") applies unchanged: cut at 0.5 T60 (-30 dB) EDT only, at
  // 1 and 2 T60 all three, within the single-estimate tolerances of the first test case.
  const double t60 = GENERATE(1.0, 0.5);
  const double cut = GENERATE(0.5, 1.0, 2.0);
  for (unsigned seed = 0; seed < 4; ++seed) {
    const std::vector<float> p = decayingNoise(t60, cut * t60, 600u + seed);
    INFO("T60 " << t60 << " s, cut at " << cut << " T60, seed " << seed);
    CHECK_FALSE(dpc::audio::findNoiseFloor(squared(p), 1.0 / kFs).found);
    const ImpulseResponseAnalysis a = analyzeImpulseResponse(p.data(), p.size(), kFs);
    CHECK(a.broadband.edt == Approx(t60).epsilon(0.05));
    if (cut < 1.0) {
      CHECK(std::isnan(a.broadband.t20));
      CHECK(std::isnan(a.broadband.t30));
    } else {
      CHECK(a.broadband.t20 == Approx(t60).epsilon(0.02));
      CHECK(a.broadband.t30 == Approx(t60).epsilon(0.02));
    }
    for (int b : {1, 4, 7}) {  // 125 Hz, 1 kHz, 8 kHz: finite where they were
      INFO("band " << bandCentreExactHz(b) << " Hz");
      const RoomParameters& r = a.bands[size_t(b)];
      CHECK(std::isfinite(r.edt));
      if (cut >= 1.0) CHECK((std::isfinite(r.t20) && std::isfinite(r.t30)));
    }
  }
}

TEST_CASE("a noise-free two-slope decay is not a floor: its slow slope is analysed as recorded") {
  // Coupled rooms and ringing modes decay in two slopes. The slow one's tail falls steadily,
  // as no stationary floor does, so no floor is found and the parameters equal those of the
  // uncompensated Schroeder curve, computed here by analyzeEnergyDecay (which looks for no
  // floor) from the same squared samples after the same onset. A floor taken there would cut
  // the slow decay off: T1 = 0.5 s, T2 = 8 T1, knee 35 dB down read T30 0.59 s against 1.20 s.
  const double ratio = GENERATE(2.5, 4.0, 6.0, 8.0);
  const double kneeDb = GENERATE(25.0, 35.0);
  const double seconds = GENERATE(1.0, 1.5);
  const double t1 = 0.5;
  for (unsigned seed = 0; seed < 2; ++seed) {
    std::vector<float> p = decayingNoise(t1, seconds, 700u + seed);
    const std::vector<float> slow = decayingNoise(ratio * t1, seconds, 800u + seed);
    const double gain = std::pow(10.0, -kneeDb / 20.0);
    for (size_t i = 0; i < p.size(); ++i) p[i] = float(double(p[i]) + gain * double(slow[i]));
    INFO("T2 / T1 " << ratio << ", knee " << kneeDb << " dB down, " << seconds << " s, seed "
                    << seed);
    const std::vector<double> e = squared(p);
    CHECK_FALSE(dpc::audio::findNoiseFloor(e, 1.0 / kFs).found);
    const double peak = *std::max_element(e.begin(), e.end());
    size_t onset = 0;
    while (e[onset] < peak / 100.0) ++onset;  // within 20 dB of the peak, as the analyser does
    const RoomParameters plain =
        analyzeEnergyDecay(e.data() + onset, e.size() - onset, 1.0 / kFs, 0.0);
    const RoomParameters r = analyzeImpulseResponse(p.data(), p.size(), kFs).broadband;
    INFO("T30 " << r.t30 << " (uncompensated " << plain.t30 << "), T20 " << r.t20 << " ("
                << plain.t20 << ")");
    CHECK(((std::isnan(r.t30) && std::isnan(plain.t30)) || r.t30 == Approx(plain.t30)));
    CHECK(((std::isnan(r.t20) && std::isnan(plain.t20)) || r.t20 == Approx(plain.t20)));
    CHECK(r.edt == Approx(plain.edt));
  }
}
