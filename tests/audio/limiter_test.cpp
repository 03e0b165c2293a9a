// Output safety limiter (audio/limiter): transparent below the ceiling, nothing above it, the
// gain reduction it reports, linked channels, and release back to unity.
#include "audio/limiter.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <vector>

using dpc::audio::Limiter;

namespace {
std::vector<float> sine(float amplitude, double hz, size_t n, int fs) {
  std::vector<float> x(n);
  for (size_t i = 0; i < n; ++i)
    x[i] = amplitude * float(std::sin(2.0 * std::numbers::pi * hz * double(i) / fs));
  return x;
}
}  // namespace

TEST_CASE("below the ceiling the limiter is bit-transparent", "[limiter]") {
  Limiter lim(48000);
  std::vector<float> x = sine(0.9f, 1000, 48000, 48000);
  const std::vector<float> ref = x;
  float* ch[1] = {x.data()};
  lim.process(ch, 1, x.size());
  CHECK(x == ref);
  CHECK(lim.limitedFrames() == 0);
  CHECK(lim.overCeilingFrames() == 0);
  CHECK(lim.maxReductionDb() == 0.f);
}

TEST_CASE("a signal 3.6 dB over full scale never exceeds the ceiling", "[limiter]") {
  const int fs = 48000;
  Limiter lim(fs);
  std::vector<float> left = sine(1.5f, 1000, fs, fs);
  std::vector<float> right = sine(0.3f, 1000, fs, fs);
  const std::vector<float> rightIn = right;
  // Blocks of 256, as the audio thread calls it.
  for (size_t start = 0; start < left.size(); start += 256) {
    float* ch[2] = {left.data() + start, right.data() + start};
    lim.process(ch, 2, std::min<size_t>(256, left.size() - start));
  }
  float peak = 0.f;
  for (float v : left) peak = std::max(peak, std::abs(v));
  CHECK(peak <= lim.ceiling());
  CHECK(lim.overCeilingFrames() > 0);
  // Largest reduction: 1.5 / ceiling at the sine's crest, 20 log10(1.5 / 0.98855) = 3.62 dB;
  // the sampled crest of a 1 kHz sine at 48 kHz lies within 0.02 dB of the true one.
  CHECK(lim.maxReductionDb() == Approx(20.0 * std::log10(1.5 / lim.ceiling())).margin(0.03));
  // Linked: the quiet channel got the same gain as the loud one, frame by frame.
  for (size_t i = 0; i < right.size(); i += 97)
    if (std::abs(rightIn[i]) > 1e-3f)
      REQUIRE(right[i] / rightIn[i] ==
              Approx(left[i] / (1.5f * std::sin(2.0 * M_PI * 1000 * i / fs))).epsilon(1e-3));
}

TEST_CASE("after a burst the gain returns to unity with the release time", "[limiter]") {
  const int fs = 48000;
  Limiter lim(fs, 0.98855f, 0.05f);
  std::vector<float> burst(480, 2.f);  // 10 ms at +6 dBFS
  float* b[1] = {burst.data()};
  lim.process(b, 1, burst.size());
  // After 5 release time constants (250 ms) the remaining reduction is e^-5 of 6.1 dB's
  // linear deficit (1 - 0.494) x 0.0067 = 0.0034: gain > 0.996.
  std::vector<float> quiet(size_t(0.25 * fs), 0.5f);
  float* q[1] = {quiet.data()};
  lim.process(q, 1, quiet.size());
  CHECK(quiet.back() / 0.5f > 0.996f);
  CHECK(quiet.front() / 0.5f < 0.5f);  // right after the burst it still holds the reduction
}
