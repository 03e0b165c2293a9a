// Tests for audio/resample: frequency, amplitude and duration survive a rate change.
#include "audio/resample.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

using dpc::audio::AudioData;
using dpc::audio::resample;

namespace {

AudioData sine(double freqHz, double amplitude, int rate, size_t frames) {
  AudioData a;
  a.sampleRate = rate;
  a.channels.assign(1, std::vector<float>(frames));
  for (size_t i = 0; i < frames; ++i)
    a.channels[0][i] =
        float(amplitude * std::sin(2 * std::numbers::pi * freqHz * double(i) / double(rate)));
  return a;
}

// Least-squares fit of a*sin + b*cos at a known frequency over [begin, end): returns amplitude
// and the RMS residual, so both a wrong frequency and a wrong level show up.
struct Fit {
  double amplitude, residualRms;
};
Fit fitSine(const std::vector<float>& x, double freqHz, int rate, size_t begin, size_t end) {
  double ss = 0, cc = 0, sc = 0, xs = 0, xc = 0;
  for (size_t i = begin; i < end; ++i) {
    const double w = 2 * std::numbers::pi * freqHz * double(i) / double(rate);
    const double s = std::sin(w), c = std::cos(w);
    ss += s * s;
    cc += c * c;
    sc += s * c;
    xs += x[i] * s;
    xc += x[i] * c;
  }
  const double det = ss * cc - sc * sc;
  const double a = (xs * cc - xc * sc) / det, b = (xc * ss - xs * sc) / det;
  double r2 = 0;
  for (size_t i = begin; i < end; ++i) {
    const double w = 2 * std::numbers::pi * freqHz * double(i) / double(rate);
    const double e = x[i] - (a * std::sin(w) + b * std::cos(w));
    r2 += e * e;
  }
  return {std::hypot(a, b), std::sqrt(r2 / double(end - begin))};
}

}  // namespace

TEST_CASE("a 1 kHz sine resampled 22050 -> 48000 keeps frequency, amplitude and phase") {
  const AudioData in = sine(1000.0, 0.5, 22050, 22050);  // 1 s
  const AudioData out = resample(in, 48000);
  REQUIRE(out.sampleRate == 48000);
  REQUIRE(out.channels.size() == 1);
  CHECK(out.frames() == 48000);  // duration scales exactly: 1 s stays 1 s
  // Away from the edges (converter start-up/flush, ~ the sinc filter's length), SRC_SINC_BEST_
  // QUALITY is documented at 97 dB SNR: errors ~1.4e-5 of full scale. The tolerances below
  // (1e-4 relative amplitude, residual 2e-4 = -74 dB re 0.5) leave room for float storage.
  const Fit fit = fitSine(out.channels[0], 1000.0, 48000, 4800, 43200);
  CHECK(fit.amplitude == Approx(0.5).epsilon(1e-4));
  CHECK(fit.residualRms < 1e-4);
  // The same fit at a frequency 1 Hz off leaves a large residual: the test can see a shift.
  const Fit wrong = fitSine(out.channels[0], 1001.0, 48000, 4800, 43200);
  CHECK(wrong.residualRms > 0.05);
}

TEST_CASE("downsampling scales duration and keeps an in-band sine") {
  const AudioData in = sine(440.0, 0.25, 48000, 24000);  // 0.5 s
  const AudioData out = resample(in, 16000);
  CHECK(out.frames() == 8000);
  const Fit fit = fitSine(out.channels[0], 440.0, 16000, 1600, 6400);
  CHECK(fit.amplitude == Approx(0.25).epsilon(1e-4));
  CHECK(fit.residualRms < 1e-4);
}

TEST_CASE("equal rates are the identity, multi-channel stays aligned") {
  AudioData in = sine(300.0, 0.3, 44100, 1000);
  in.channels.push_back(in.channels[0]);
  CHECK(resample(in, 44100).channels == in.channels);
  const AudioData out = resample(in, 48000);
  REQUIRE(out.channels.size() == 2);
  CHECK(out.channels[0] == out.channels[1]);
}

TEST_CASE("invalid rates are refused") {
  const AudioData in = sine(300.0, 0.3, 44100, 100);
  CHECK_THROWS_AS(resample(in, 0), std::invalid_argument);
  CHECK_THROWS_AS(resample(in, 44100 * 300), std::invalid_argument);
}
