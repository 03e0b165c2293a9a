// Tests for audio/panning: the constant-power sine/cosine pan law.
#include "audio/panning.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

using dpc::audio::stereoGains;

namespace {
struct Gains {
  float left, right;
};
Gains gains(float x, float y, float z) {
  const float d[3] = {x, y, z};
  Gains g;
  stereoGains(d, &g.left, &g.right);
  return g;
}
}  // namespace

TEST_CASE("centre gives equal gains at -3 dB") {
  for (const Gains g : {gains(1, 0, 0), gains(-1, 0, 0), gains(0, 0, 1), gains(0.3f, 0, -0.9f)}) {
    CHECK(g.left == Approx(g.right).margin(1e-7));
    CHECK(20 * std::log10(g.left) == Approx(-3.0103).margin(1e-3));
  }
}

TEST_CASE("hard left gives (1, 0), hard right (0, 1)") {
  const Gains l = gains(0, 1, 0), r = gains(0, -1, 0);
  CHECK(l.left == Approx(1.0f).margin(1e-7));
  CHECK(l.right == Approx(0.0f).margin(1e-7));
  CHECK(r.left == Approx(0.0f).margin(1e-7));
  CHECK(r.right == Approx(1.0f).margin(1e-7));
  // Length does not matter, elevation is ignored.
  const Gains l2 = gains(0, 5, 3);
  CHECK(l2.left == Approx(1.0f).margin(1e-7));
}

TEST_CASE("front and back fold onto the same pan position, gains rise towards the side") {
  const Gains front = gains(1, 1, 0), back = gains(-1, 1, 0);
  CHECK(front.left == Approx(back.left).margin(1e-7));
  CHECK(front.right == Approx(back.right).margin(1e-7));
  // 45 degrees left: p = 0.75, gL = sin(3 pi / 8).
  CHECK(front.left == Approx(std::sin(3 * std::numbers::pi / 8)).margin(1e-6));
  float previous = -1;
  for (int deg = -90; deg <= 90; deg += 5) {
    const float a = float(deg * std::numbers::pi / 180);
    const Gains g = gains(std::cos(a), std::sin(a), 0);
    CHECK(g.left > previous);
    previous = g.left;
  }
}

TEST_CASE("power sums to 1 for random directions, degenerate input included") {
  std::mt19937 rng(1);
  std::normal_distribution<float> n;
  for (int i = 0; i < 10000; ++i) {
    const Gains g = gains(n(rng), n(rng), n(rng));
    CHECK(g.left * g.left + g.right * g.right == Approx(1.0f).margin(1e-6));
    CHECK(g.left >= 0);
    CHECK(g.right >= 0);
  }
  const Gains z = gains(0, 0, 0), nan = gains(std::nanf(""), 1, 0);
  CHECK(z.left == Approx(z.right));
  CHECK(nan.left == Approx(nan.right));
}
