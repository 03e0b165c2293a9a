// The two-channel (binaural, stereo) IR synthesis adds no error to each ear's band parameters:
// the ISO 3382-1 band analysis of an ear's IR returns the parameters of the energy response
// that ear receives (every direction's response weighted by that ear's filter, plus the
// direct sound through its exact filter), as closely as an exact IR of that response would.
// The room decays like a large hall: air absorption makes 8 kHz fall three times faster than
// 1 kHz, where the gain steps of the slower bands splatter into the faster ones.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <vector>

#include "analysis/room_parameters.h"
#include "runtime/output_format.h"
#include "runtime/render_pipeline.h"
#include "synthesis/spatial_synthesizer.h"
#include "tests/apps/band_readings.h"

using namespace dpc;
using test::strengthDbOf;

namespace {

constexpr int kFs = 48000;

/// Per ear: its energy response and direct sound.
struct EarResponse {
  EnergyResponse er;
  DirectSound direct;
};

/// A hall's late field from 15 ms on: diffuse with per-band T60 `t60`, plus a lateral part.
DirectionalEnergyResponse hallLateField(double length, const std::array<double, kNumBands>& t60,
                                        const std::vector<glm::vec3>& dirs) {
  DirectionalEnergyResponse energy(length, 1e-3, dirs);
  for (size_t k = 15; k < size_t(length * 1e3) - 1; ++k) {
    const double t = (double(k) + 0.5) * 1e-3;
    Bands e;
    for (int b = 0; b < kNumBands; ++b)
      e[b] = float(4e-5 * std::pow(10.0, -6.0 * t / t60[size_t(b)]));
    const double lateral = std::exp(-t / 0.1);
    for (const glm::vec3& w : {glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0),
                               glm::vec3(0, -1, 0), glm::vec3(0, 0, 1), glm::vec3(0, 0, -1)}) {
      Bands share = e;
      for (int b = 0; b < kNumBands; ++b) share[b] *= float(1.0 / 6.0);
      energy.add(t, share, w);
    }
    Bands side = e;
    for (int b = 0; b < kNumBands; ++b) side[b] *= float(lateral);
    energy.add(t, side, glm::normalize(glm::vec3(1, 0, -1)));  // front left (world)
  }
  return energy;
}

/// What ear `ear` receives: every direction's response and the direct sound, weighted per ear.
EarResponse earResponse(double length, const DirectionalEnergyResponse& energy,
                        const DirectSound& direct, const SpatialIrSynthesizer& synth, int ear) {
  EarResponse want{EnergyResponse(length, 1e-3), direct};
  for (size_t d = 0; d < energy.directionCount(); ++d)
    for (size_t k = 0; k < want.er.binCount(); ++k)
      for (int b = 0; b < kNumBands; ++b)
        want.er.bins()[k][b] +=
            energy.response(d).bins()[k][b] * synth.channelWeight(d, size_t(ear))[b];
  for (int b = 0; b < kNumBands; ++b)
    want.direct.intensity[b] = direct.intensity[b] * synth.directWeight(size_t(ear))[b];
  return want;
}

}  // namespace

TEST_CASE("Two-channel IR: each ear's band analysis returns its energy response's T30, C80 and G",
          "[synthesis][spatial][statistics]") {
  const double length = 2.5;
  // T60 per band (63 Hz .. 8 kHz): a hall with air absorption.
  const std::array<double, kNumBands> t60{2.6, 2.6, 2.5, 2.4, 2.2, 1.9, 1.4, 0.8};
  const std::vector<glm::vec3> dirs = defaultSpatialDirections();
  for (OutputFormat format : {OutputFormat::kBinaural, OutputFormat::kStereo}) {
    SceneDesc scene;
    scene.audio.output = format;
    PropagationSettings ps;
    ps.irLength = float(length);
    for (uint64_t seed : {1u, 2u, 3u, 4u, 5u, 6u}) {
      ps.seed = seed;
      const double volume = 1000.0;
      auto synth = makeSpatialSynthesizer(scene, ps, volume);
      // The late field: from 15 ms on, arriving from all directions, more from the front
      // left early on (a lateral reflection pattern), diffuse later. 1000 m^3: the density
      // law gives an early part that the Dirac sequences can carry (see the tolerances).
      const DirectionalEnergyResponse energy = hallLateField(length, t60, dirs);
      DirectSound direct;
      direct.visible = true;
      direct.delaySeconds = 0.008f;
      direct.distance = 0.008f * 343.f;
      direct.direction = glm::normalize(glm::vec3(1, 0.2f, 0.5f));  // front right, above
      for (int b = 0; b < kNumBands; ++b) direct.intensity[b] = 2e-3f;
      std::vector<float> left(synth->lengthSamples()), right(synth->lengthSamples());
      synth->synthesize(energy, direct, std::array<float*, 2>{left.data(), right.data()});

      for (int ear = 0; ear < 2; ++ear) {
        const EarResponse want = earResponse(length, energy, direct, *synth, ear);
        const test::ResponseBands bands(want.er, want.direct, kFs);
        // From 250 Hz: the bands rendered per direction and levelled per ear (63/125 Hz are
        // one omnidirectional rendering fed to both ears, see synthesis/spatial_synthesizer.h).
        for (const auto& [b, target, exact, got] :
             bands.read(ear == 0 ? left : right, SpatialIrSynthesizer::kDirectionalFromBand)) {
          std::printf(
              "%s seed %d ear %d band %4d Hz: T30 response %.3f exact IR %.3f synthesised %.3f; "
              "C80 %+.2f / %+.2f / %+.2f dB; G %+.2f / %+.2f / %+.2f dB\n",
              format == OutputFormat::kBinaural ? "binaural" : "stereo", int(seed), ear,
              int(kBandCentreHz[size_t(b)]), target.t30, exact.t30, got.t30, target.c80, exact.c80,
              got.c80, strengthDbOf(target), strengthDbOf(exact), strengthDbOf(got));
          INFO("format " << int(format) << " seed " << seed << " ear " << ear << " band " << b);
          // Tolerances. The per-ear levelling matches the analysed energy in 50 ms windows
          // from 20 ms after the direct sound, so T30 keeps what a window's resolution on a
          // steep slope and one realisation's noise leave (measured up to 3.2 % over at 4 kHz
          // binaural, 7.1 % at 8 kHz stereo, where the band decays 60 dB in 0.8 s: 8 %). C80
          // keeps the early part's error: each direction's Dirac sequence follows the
          // reflection density law (Kuttruff eq. 4.6), 115 pulses/s at 15 ms in 1000 m^3, so
          // an early bin without a pulse passes its energy to the nearer bin with one, possibly
          // across 80 ms (measured up to 0.9 dB beyond an exact IR's deviation: 1.5 dB). G:
          // 0.5 dB beyond an exact IR's; binaural 0.75 dB: the exact IR's model is flat within
          // each band, while an HRTF's slope inside an octave (rising from 1 to 3 kHz toward the
          // ear canal's resonance) weights the analysis filter's skirts otherwise than the
          // synthesis masks that set the level (measured up to 0.63 dB low at 1 kHz, 0.3 dB of
          // it with the direct sound off). Without the levelling the 8 kHz T30 reads over twice
          // the response's.
          CHECK(got.t30 < std::max(target.t30, exact.t30) * 1.08);
          CHECK(got.t30 > std::min(target.t30, exact.t30) * 0.97);
          CHECK(std::abs(got.c80 - target.c80) < std::abs(exact.c80 - target.c80) + 1.5);
          CHECK(std::abs(strengthDbOf(got) - strengthDbOf(target)) <
                std::abs(strengthDbOf(exact) - strengthDbOf(target)) +
                    (format == OutputFormat::kBinaural ? 0.75 : 0.5));
        }
      }
    }
  }
}

TEST_CASE("Two-channel IR in an open scene's volume: sparse pulses, every band's energy kept",
          "[synthesis][spatial]") {
  // An open scene's bounding volume (1e9 m^3): the density law alone gives each direction's
  // Dirac sequence about one pulse per second, so an early reflection's energy would wait up
  // to a second for a pulse and empty directions would lose theirs. With the density floor
  // (kMinPulseDensity, 100 pulses/s) a bin's energy goes to the nearer pulse, and the bins
  // between pulses keep that pulse's gain so that its band- and ear-filtered waveform (the
  // HRIR's delay moves it into the next bin) sounds whole. Most of this response's energy
  // lies in its first 100 ms, about ten pulses per direction, whose filtered responses overlap
  // with random signs: a band's energy scatters about its target by about 1 dB (measured up
  // to 1.4 dB over seeds 3 and 4, two ears, 250 Hz-8 kHz; mean +0.25 dB). Tolerances: each
  // within 2 dB, the mean (the systematic part) within 0.5 dB. Without the floor and the gains
  // the bands read 1 to 11 dB low (mean -6 dB).
  const double length = 2.0, volume = 1e9;
  const std::vector<glm::vec3> dirs = defaultSpatialDirections();
  SceneDesc scene;
  scene.audio.output = OutputFormat::kBinaural;
  PropagationSettings ps;
  ps.irLength = float(length);
  double sumDb = 0.0;
  int count = 0;
  for (uint64_t seed : {3u, 4u}) {
    ps.seed = seed;
    auto synth = makeSpatialSynthesizer(scene, ps, volume);
    // A ground reflection 2 ms after the direct sound and a short decay (T60 0.4 s) from two
    // directions: an open space's early-heavy response.
    DirectionalEnergyResponse energy(length, 1e-3, dirs);
    Bands reflection;
    for (int b = 0; b < kNumBands; ++b) reflection[b] = 1e-3f;
    energy.add(0.0125, reflection, glm::normalize(glm::vec3(1, 0, -1)));
    for (size_t k = 20; k < size_t(length * 1e3) - 1; ++k) {
      const double t = (double(k) + 0.5) * 1e-3;
      Bands e;
      for (int b = 0; b < kNumBands; ++b) e[b] = float(1e-4 * std::pow(10.0, -6.0 * t / 0.4));
      energy.add(t, e, glm::vec3(1, 0, 0));
      energy.add(t, e, glm::vec3(0, 1, 0));
    }
    DirectSound direct;
    direct.visible = false;
    std::vector<float> left(synth->lengthSamples()), right(synth->lengthSamples());
    synth->synthesize(energy, direct, std::array<float*, 2>{left.data(), right.data()});
    for (int ear = 0; ear < 2; ++ear) {
      const std::vector<float>& ir = ear == 0 ? left : right;
      for (float x : ir) REQUIRE(std::isfinite(x));
      const auto a = audio::analyzeImpulseResponse(ir.data(), ir.size(), kFs);
      for (int b = SpatialIrSynthesizer::kDirectionalFromBand; b < kNumBands; ++b) {
        double want = 0.0;
        for (size_t d = 0; d < dirs.size(); ++d)
          for (size_t k = 0; k < energy.response(d).binCount(); ++k)
            want +=
                double(energy.response(d).bins()[k][b]) * synth->channelWeight(d, size_t(ear))[b];
        const double db = 10 * std::log10(a.bands[size_t(b)].energy / want);
        std::printf("open scene seed %d ear %d band %4d Hz: %+.2f dB re target\n", int(seed), ear,
                    int(kBandCentreHz[size_t(b)]), db);
        INFO("seed " << seed << " ear " << ear << " band " << b);
        CHECK(std::abs(db) < 2.0);
        sumDb += db;
        ++count;
      }
    }
  }
  CHECK(std::abs(sumDb / count) < 0.5);
}
