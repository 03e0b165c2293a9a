// One synthesised IR, not an ensemble, carries its energy response's octave parameters: the
// ISO 3382-1 band analysis of a single IR (analyzeImpulseResponse) reads the G, C80 and EDT
// that the same analysis reads from an exact IR of the response (expectedBandAnalysisEnergy,
// dpc-analyze --as-measured), 250 Hz - 4 kHz, in three room-like responses (a direct sound,
// early reflections, a diffuse decay per band with air absorption, and the bin-to-bin scatter
// of a traced response) for 4 seeds each.
//
// Tolerances, from the Monte Carlo scatter of the band noise: without the per-realisation
// levelling (the band noise alone) one IR scatters around the exact IR's
// reading by G 0.62 / 0.47 / 0.31 / 0.27 / 0.13 dB RMS, C80 1.25 / 0.84 / 0.56 / 0.54 / 0.34 dB
// and EDT 14 / 12 / 4.8 / 7.6 / 4.9 % at 250 Hz .. 4 kHz over these 12 IRs. The test asks, per
// band over the 12, for an RMS within the tolerances (G 0.3 dB, C80 0.5 dB, EDT 5 %:
// a third, a half and one of ISO 3382-1's just noticeable differences), which the noise alone
// fails at 250 Hz - 2 kHz, for every single IR within twice them (the mono IRs within 1.5
// times, below), and for no bias: the mean over the 12 within 3 standard errors or a third of
// the tolerance of 0, whichever is larger.
//
// A first-order AmbiX IR is checked alike per channel in its window-levelled bands (250 Hz -
// 1 kHz), a stereo IR per channel at 250 Hz - 4 kHz, a binaural IR per ear at 250 Hz - 4 kHz
// against an exact IR through the HRIRs.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "analysis/room_parameters.h"
#include "audio/hrtf.h"
#include "common/fftw_util.h"
#include "common/octave_band_masks.h"
#include "common/octave_filter.h"
#include "runtime/propagation_stage.h"
#include "synthesis/mono_synthesizer.h"
#include "synthesis/spatial_synthesizer.h"
#include "tests/apps/band_readings.h"

using namespace dpc;
using test::strengthDbOf;

namespace {

constexpr int kFs = 48000;
constexpr double kLength = 2.0;

/// The tolerances of one IR against an exact IR's reading (ISO 3382-1 annex A's just
/// noticeable differences are 1 dB, 1 dB and 5 %; these ask for a third, a half and one).
constexpr double kG = 0.3, kC80 = 0.5, kEdt = 0.05;

/// A room: volume (m^3), T60 per band (s), source distance (m), reverberant level re the
/// direct sound, first reflection delay after the direct sound (s).
struct Room {
  const char* name;
  double volume;
  std::array<double, kNumBands> t60;
  double distance, reverberant, firstReflection;
};

const Room kRooms[] = {
    {"small", 60.0, {0.7, 0.6, 0.5, 0.45, 0.45, 0.45, 0.4, 0.35}, 2.5, 1.5, 0.002},
    {"classroom", 300.0, {1.1, 1.0, 0.9, 0.8, 0.8, 0.75, 0.7, 0.55}, 6.0, 3.0, 0.004},
    {"hall", 3000.0, {2.2, 2.0, 1.9, 1.8, 1.7, 1.5, 1.2, 0.8}, 12.0, 4.0, 0.008},
};

/// Per band: the late field's energy per 1 ms bin from the first reflection on, decaying with
/// T60, its bins scattered as a traced response's are (each bin times a gamma variate of mean 1,
/// shape 8: a few dozen paths per bin), plus six early reflections of 3..12 % of the direct
/// sound each within 40 ms. Filled into `add(k, bands)` (k the bin).
template <class Add>
void roomResponse(const Room& room, const DirectSound& direct, Add add) {
  std::mt19937 rng(7);
  std::gamma_distribution<double> scatter(8.0, 1.0 / 8.0);
  const size_t k0 = size_t(direct.delaySeconds / 1e-3 + room.firstReflection / 1e-3);
  const double directEnergy = direct.intensity[4];
  for (size_t k = k0; k < size_t(kLength * 1e3) - 1; ++k) {
    const double t = double(k - k0) * 1e-3;
    const double s = scatter(rng);
    Bands e;
    for (int b = 0; b < kNumBands; ++b) {
      const double t60 = room.t60[size_t(b)];
      // The late field's total is `reverberant` x the direct sound: E0 T60 / (6 ln 10 x 1 ms).
      const double e0 = room.reverberant * directEnergy * 1e-3 * 6.0 * std::log(10.0) / t60;
      e[b] = float(e0 * s * std::pow(10.0, -6.0 * t / t60));
    }
    add(k, e);
  }
  std::uniform_real_distribution<double> when(0.0, 0.04), share(0.03, 0.12);
  for (int i = 0; i < 6; ++i) {
    const size_t k = k0 + size_t(when(rng) / 1e-3);
    add(k, Bands(float(share(rng) * directEnergy)));
  }
}

DirectSound directFor(const Room& room) {
  DirectSound d;
  d.visible = true;
  d.distance = float(room.distance);
  d.delaySeconds = float(room.distance / 343.0);
  d.intensity = Bands(float(1.0 / (4.0 * std::numbers::pi * room.distance * room.distance)));
  d.direction = glm::normalize(glm::vec3(1.f, 0.3f, -0.4f));
  return d;
}

/// One band of one IR against the exact IR's reading: G and C80 differences (dB) and the EDT
/// ratio - 1; printed.
struct Difference {
  double g, c80, edt;
};

Difference differenceOf(const char* what, const test::BandReading& r) {
  const Difference d{strengthDbOf(r.ir) - strengthDbOf(r.exactIr), r.ir.c80 - r.exactIr.c80,
                     r.ir.edt / r.exactIr.edt - 1.0};
  std::printf("%s band %4d Hz: G %+.2f dB, C80 %+.2f dB, EDT %+.1f %%\n", what,
              int(kBandCentreHz[size_t(r.band)]), d.g, d.c80, 100 * d.edt);
  return d;
}

/// Checks one band's differences over rooms and seeds: RMS within (kG, kC80, kEdt), each
/// within `largest` times that, the mean within 3 standard errors (or a third of the
/// tolerance) of 0.
void checkBand(int band, const std::vector<Difference>& v, double largestFactor = 2.0) {
  const double n = double(v.size());
  auto stats = [&](double Difference::*m, double tolerance, const char* name) {
    double sum = 0.0, sum2 = 0.0, largest = 0.0;
    for (const Difference& d : v) {
      sum += d.*m;
      sum2 += d.*m * d.*m;
      largest = std::max(largest, std::abs(d.*m));
    }
    const double mean = sum / n, rms = std::sqrt(sum2 / n);
    const double se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1.0));
    std::printf("band %4d Hz %s: RMS %.3f, mean %+.3f +- %.3f, largest %.3f (n %d)\n",
                int(kBandCentreHz[size_t(band)]), name, rms, mean, se, largest, int(n));
    INFO("band " << kBandCentreHz[size_t(band)] << " Hz " << name << ": RMS " << rms << " mean "
                 << mean << " +- " << se << " largest " << largest);
    CHECK(rms <= tolerance);
    CHECK(largest <= largestFactor * tolerance);
    CHECK(std::abs(mean) <= std::max(3.0 * se, tolerance / 3.0));
  };
  stats(&Difference::g, kG, "G (dB)");
  stats(&Difference::c80, kC80, "C80 (dB)");
  stats(&Difference::edt, kEdt, "EDT (ratio - 1)");
}

/// Bands checked: 250 Hz .. 4 kHz.
constexpr int kFirstBand = 2, kLastBand = 6;

}  // namespace

TEST_CASE("One mono IR reads its response's octave G, C80 and EDT, for every seed",
          "[synthesis][single_ir][statistics]") {
  std::array<std::vector<Difference>, kNumBands> diffs;
  for (const Room& room : kRooms) {
    const DirectSound direct = directFor(room);
    EnergyResponse er(kLength, 1e-3);
    roomResponse(room, direct, [&](size_t k, const Bands& e) { er.bins()[k] += e; });
    const test::ResponseBands bands(er, direct, kFs);
    for (uint64_t seed : {1u, 2u, 3u, 4u}) {
      IrSynthesizer synth(kFs, kLength, room.volume, 343.0, seed);
      std::vector<float> ir(synth.lengthSamples());
      synth.synthesize(er, direct, ir.data());
      for (const test::BandReading& r : bands.read(ir, kFirstBand)) {
        if (r.band > kLastBand) continue;
        char what[64];
        std::snprintf(what, sizeof what, "mono %s seed %d", room.name, int(seed));
        diffs[size_t(r.band)].push_back(differenceOf(what, r));
      }
    }
  }
  // Each single IR within 1.5x the tolerances: the RMS is about half of them or less in every
  // band (G 0.12, C80 0.21 dB, EDT 2.6 % at most), and the largest of 12 normal draws lies
  // about 2.2 RMS out. With the fixed part's cross term free to raise a window's factor to 2x
  // (synthesis/window_leveller.h), the small room's 250 Hz C80 read +0.82 dB and this fails.
  for (int b = kFirstBand; b <= kLastBand; ++b) checkBand(b, diffs[size_t(b)], 1.5);
}

namespace {

/// The room's response spread over the synthesiser's directions: the direct sound's direction
/// takes a third of the early reflections, the late field is diffuse (each bin's energy split
/// over the directions with random shares, as a traced response's few paths per bin are).
DirectionalEnergyResponse directionalResponse(const Room& room, const DirectSound& direct,
                                              const std::vector<glm::vec3>& dirs) {
  DirectionalEnergyResponse energy(kLength, 1e-3, dirs);
  std::mt19937 rng(11);
  std::gamma_distribution<double> share(4.0, 1.0);
  roomResponse(room, direct, [&](size_t k, const Bands& e) {
    std::vector<double> w(dirs.size());
    double sum = 0.0;
    for (double& x : w) sum += x = share(rng);
    for (size_t d = 0; d < dirs.size(); ++d)
      for (int b = 0; b < kNumBands; ++b)
        energy.response(d).bins()[k][b] += float(double(e[b]) * w[d] / sum);
  });
  return energy;
}

/// What the ISO 3382-1 octave filters (common/octave_filter.h, those of
/// analyzeImpulseResponse) read of white noise through a direction's filter `taps` and the
/// synthesiser's per-band diffuse-field equalisation (sum_k M_k^2 sqrt(diffuseFieldGain(k)), M_k
/// the band masks of common/octave_band_masks.h), over what they read of the flat band model
/// that the band weights w stand for (density sum_k w_k M_k^2, as expectedBandAnalysisEnergy
/// models a response). An HRIR is not flat within an octave (KEMAR's ear-canal rise puts the
/// 2 kHz band's reading 0.7 dB above the model, the 1 kHz band's 0.5 dB below, averaged over
/// the 8 directions), so an exact binaural IR of a response reads this much off the model.
/// Both read as impulse responses: a deterministic signal's band energy is white noise's
/// expected one through the same filter.
Bands filterShapeRatio(const std::vector<float>& taps, const Bands& w,
                       const SpatialIrSynthesizer& synth) {
  constexpr size_t n = 32768;  // the zero-phase equaliser's ringing and the HRIR fit in n / 2
  static FftwRealTransforms fft(n);
  static const OctaveBandMasks masks(kFs, n);
  const auto read = [&](bool shaped) {
    std::fill(fft.time.p, fft.time.p + n, 0.f);
    std::copy(taps.begin(), taps.end(), fft.time.p);
    fftwf_execute(fft.fwd);
    for (size_t k = 0; k < n / 2 + 1; ++k) {
      double eq = 0.0, model = 0.0;
      for (int b = 0; b < kNumBands; ++b) {
        const double m2 = double(masks.gain(b, k)) * masks.gain(b, k);
        eq += m2 * std::sqrt(synth.diffuseFieldGain(b));
        model += m2 * w[b];
      }
      for (int i = 0; i < 2; ++i)
        fft.band.p[k][i] = shaped ? float(fft.spec.p[k][i] * eq / n)
                                  : float(i == 0 ? std::sqrt(model) / n : 0.0);
    }
    fftwf_execute(fft.inv);
    std::vector<double> x(2 * n, 0.0);  // centred (zero-phase parts at negative times), rung out
    for (size_t t = 0; t < n; ++t) x[(t + n / 2) % n] = fft.time.p[t];
    Bands e(0.f);
    for (int b = 0; b < kNumBands; ++b) {
      std::vector<double> y(x.size());
      OctaveBandPass::State state{};
      OctaveBandPass::design(bandCentreExactHz(b), kFs).run(x.data(), y.data(), x.size(), state);
      double sum = 0.0;
      for (double v : y) sum += v * v;
      e[b] = float(sum);
    }
    return e;
  };
  const Bands shaped = read(true), flat = read(false);
  Bands ratio(1.f);
  for (int b = 0; b < kNumBands; ++b) ratio[b] = flat[b] > 0.f ? shaped[b] / flat[b] : 1.f;
  return ratio;
}

/// A direction's HRIR for one ear (c: 0 left, 1 right), as the binaural output fills it.
std::vector<float> hrirOf(const audio::Hrtf& hrtf, const glm::vec3& v, size_t c) {
  const float dir[3] = {v.x, v.y, v.z};
  std::vector<float> l(size_t(hrtf.filterLength())), r(l.size());
  float dl = 0.f, dr = 0.f;
  hrtf.hrir(dir, l.data(), r.data(), &dl, &dr);
  return c == 0 ? l : r;
}

/// Channel c's response: every direction's weighted by the channel's filter (below
/// kDirectionalFromBand by the omnidirectional noise's gain, as the synthesiser renders those
/// bands), and the direct sound through its exact filter (what the per-channel levelling aims
/// at); with an HRTF, besides, how much an exact IR through those filters reads off the flat
/// band model per band (filterShapeRatio): of the reverberant part, averaged over the
/// directions by their band energy in the channel, and of the direct sound.
struct ChannelResponse {
  EnergyResponse er;
  DirectSound direct;
  Bands reverberantScale{1.f}, directScale{1.f};
};

ChannelResponse channelResponse(const DirectionalEnergyResponse& energy, const DirectSound& direct,
                                const SpatialIrSynthesizer& synth, size_t c,
                                const audio::Hrtf* hrtf) {
  ChannelResponse out{EnergyResponse(kLength, 1e-3), direct};
  Bands weighted(0.f), total(0.f);
  for (size_t d = 0; d < energy.directionCount(); ++d) {
    Bands band(0.f);
    for (size_t k = 0; k < out.er.binCount(); ++k)
      for (int b = 0; b < kNumBands; ++b) {
        const float w = b < kDirectionalFromBand ? synth.omniGain(c) * synth.omniGain(c)
                                                 : synth.channelWeight(d, c)[b];
        out.er.bins()[k][b] += energy.response(d).bins()[k][b] * w;
        band[b] += energy.response(d).bins()[k][b] * w;
      }
    if (!hrtf) continue;
    const Bands r = filterShapeRatio(hrirOf(*hrtf, synth.directions()[d], c),
                                     synth.channelWeight(d, c), synth);
    for (int b = kDirectionalFromBand; b < kNumBands; ++b) {
      weighted[b] += r[b] * band[b];
      total[b] += band[b];
    }
  }
  for (int b = 0; b < kNumBands; ++b)
    out.direct.intensity[b] = direct.intensity[b] * synth.directWeight(c)[b];
  if (!hrtf) return out;
  for (int b = kDirectionalFromBand; b < kNumBands; ++b)
    if (total[b] > 0.f) out.reverberantScale[b] = weighted[b] / total[b];
  out.directScale = filterShapeRatio(hrirOf(*hrtf, energy.toListener(direct.direction), c),
                                     synth.directWeight(c), synth);
  return out;
}

/// Synthesises one IR of `scene`'s spatial format per room and seed and calls
/// use(what, channel, reading) for every channel's band reading from 250 Hz to lastBand, the
/// reading against an exact IR of that channel's own share (channelResponse).
template <class Use>
void forEachChannelReading(const SceneDesc& scene, const char* name, int lastBand, Use use) {
  PropagationSettings ps;
  ps.irLength = float(kLength);
  const std::unique_ptr<audio::Hrtf> hrtf =
      scene.audio.output == OutputFormat::kBinaural
          ? std::make_unique<audio::Hrtf>(audio::Hrtf::load(scene.audio.hrtfPath, kFs))
          : nullptr;
  for (const Room& room : kRooms) {
    const DirectSound direct = directFor(room);
    for (uint64_t seed : {1u, 2u, 3u, 4u}) {
      ps.seed = seed;
      auto synth = makeSpatialSynthesizer(scene, ps, room.volume);
      const DirectionalEnergyResponse energy =
          directionalResponse(room, direct, synth->directions());
      std::vector<std::vector<float>> out(synth->channelCount(),
                                          std::vector<float>(synth->lengthSamples()));
      std::vector<float*> ptrs;
      for (auto& o : out) ptrs.push_back(o.data());
      synth->synthesize(energy, direct, ptrs);
      for (size_t c = 0; c < synth->channelCount(); ++c) {
        const ChannelResponse cr = channelResponse(energy, direct, *synth, c, hrtf.get());
        const test::ResponseBands bands(cr.er, cr.direct, kFs, cr.reverberantScale,
                                        cr.directScale);
        for (const test::BandReading& r : bands.read(out[c], kFirstBand)) {
          if (r.band > lastBand) continue;
          char what[96];
          std::snprintf(what, sizeof what, "%s %s seed %d channel %d", name, room.name,
                        int(seed), int(c));
          use(what, c, r);
        }
      }
    }
  }
}

}  // namespace

namespace {

/// Every channel of one `output` IR per room and seed, 250 Hz - 4 kHz, checked as the mono case
/// is (checkBand) over the 12 IRs x 2 channels; each single channel-IR within 2.3x the
/// tolerance at 250 Hz - 1 kHz (the largest of 24 normal draws lies about sqrt(2 ln 24) = 2.5
/// standard deviations out against 2.2 for the mono case's 12, so its 2x scales to 2.3x), and
/// within the tolerance itself at 2 and 4 kHz: there a window of a channel holds many pulses
/// of K directions, so the RMS is a quarter of the tolerance or less and 2.5 of it stay inside
/// (levelled on the analysis filters over 50 ms instead, one stereo 2 kHz EDT read 10 %).
void checkTwoChannelFormat(OutputFormat output, const char* name) {
  SceneDesc scene;
  scene.audio.output = output;
  std::array<std::vector<Difference>, kNumBands> diffs;
  forEachChannelReading(scene, name, kLastBand,
                        [&](const char* what, size_t, const test::BandReading& r) {
                          diffs[size_t(r.band)].push_back(differenceOf(what, r));
                        });
  for (int b = kFirstBand; b <= kLastBand; ++b) {
    INFO(name);
    checkBand(b, diffs[size_t(b)], b > IrSynthesizer::kLastLevelledBand ? 1.0 : 2.3);
  }
}

}  // namespace

TEST_CASE("One stereo IR: each channel reads its own share's octave G, C80 and EDT",
          "[synthesis][single_ir][statistics]") {
  // Window-levelled per channel at 125 Hz - 4 kHz (synthesis/channel_levelling.h), the band
  // leveller at 8 kHz. Levelled on the analysis filters over 50 ms instead, 2 kHz's EDT read up
  // to 10 % off in the small room. Without the window levelling the 250 Hz band fails (G RMS 0.47 dB, C80 RMS
  // 0.71 dB, EDT RMS 7.4 %, largest 21 %).
  checkTwoChannelFormat(OutputFormat::kStereo, "stereo");
}

TEST_CASE("One binaural IR: each ear reads its own share's octave G, C80 and EDT",
          "[synthesis][single_ir][statistics]") {
  // Each ear against an exact IR through the HRIRs (channelResponse: the flat band model
  // scaled by filterShapeRatio). The window levelling sees each ear's direct sound and exact
  // paths beside its reverberant part; without that the 250 Hz band fails (G RMS 0.32 dB,
  // largest 0.78 dB: the small room's direct sound and the field's start add in pressure).
  checkTwoChannelFormat(OutputFormat::kBinaural, "binaural");
}

TEST_CASE("One first-order AmbiX IR: each channel reads its own share's octave parameters",
          "[synthesis][single_ir][statistics]") {
  // The window-levelled bands of an Ambisonic IR (125 Hz - 1 kHz, each channel against its own
  // share of the directional response), checked as the mono case is over the 12 IRs x 4
  // channels; 250 Hz - 1 kHz (the 125 Hz band's C80 and EDT read too few periods per window).
  // Each single channel-IR within 2.5x the tolerance: the largest of 48 normal draws lies
  // about sqrt(2 ln 48) = 2.8 standard deviations out against 2.2 for the mono case's 12, so
  // its 2x scales to 2.5x. Without the per-channel levelling this fails at every band (C80
  // RMS 0.79 / 0.43 / 0.35 dB, G up to 1.6 dB, EDT RMS 9.5 % at 250 Hz).
  SceneDesc scene;
  scene.audio.output = OutputFormat::kAmbisonics;
  scene.audio.ambisonicOrder = 1;
  std::array<std::vector<Difference>, kNumBands> diffs;
  std::array<std::vector<Difference>, kNumBands> w;  // W at 2 and 4 kHz
  forEachChannelReading(scene, "ambix", kLastBand,
                        [&](const char* what, size_t c, const test::BandReading& r) {
                          if (r.band <= IrSynthesizer::kLastLevelledBand)
                            diffs[size_t(r.band)].push_back(differenceOf(what, r));
                          else if (c == 0)
                            w[size_t(r.band)].push_back(differenceOf(what, r));
                        });
  for (int b = kFirstBand; b <= IrSynthesizer::kLastLevelledBand; ++b)
    checkBand(b, diffs[size_t(b)], 2.5);
  // W, which a user reads as the omnidirectional IR, is window-levelled up to 4 kHz as a stereo
  // channel is (SpatialIrSynthesizer::lastWindowLevelledBandOf): each of its 12 IRs within the
  // tolerances there, as a stereo channel's 24.
  for (int b = IrSynthesizer::kLastLevelledBand + 1; b <= kLastBand; ++b) {
    INFO("W");
    checkBand(b, w[size_t(b)], 1.0);
  }
}

