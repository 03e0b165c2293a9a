// Tests for audio/vbap: Pulkki's vector base amplitude panning over 2-D and 3-D layouts.
#include "audio/vbap.h"

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

using dpc::audio::Vbap;

namespace {

using Angles = std::vector<std::array<double, 2>>;

// 5.1 and 7.1.4 without LFE (ITU-R BS.775, BS.2051; scene/loudspeaker_layout.h); a dome:
// 8 on the horizon, 6 at 40 degrees, 1 at the zenith.
const Angles k51 = {{30, 0}, {-30, 0}, {0, 0}, {110, 0}, {-110, 0}};
const Angles k714 = {{30, 0},   {-30, 0},    {0, 0},   {135, 0},  {-135, 0}, {90, 0},
                     {-90, 0},  {45, 30},    {-45, 30}, {135, 30}, {-135, 30}};
Angles dome() {
  Angles a;
  for (int k = 0; k < 8; ++k) a.push_back({-180.0 + 45.0 * k, 0});
  for (int k = 0; k < 6; ++k) a.push_back({-150.0 + 60.0 * k, 40});
  a.push_back({0, 90});
  return a;
}

std::array<float, 3> dirOf(double az, double el) {
  const double d = std::numbers::pi / 180;
  return {float(std::cos(el * d) * std::cos(az * d)), float(std::cos(el * d) * std::sin(az * d)),
          float(std::sin(el * d))};
}

}  // namespace

TEST_CASE("VBAP: a source at a loudspeaker plays from that loudspeaker alone") {
  for (const Angles& layout : {k51, k714, dome()}) {
    const Vbap v(layout);
    for (size_t s = 0; s < layout.size(); ++s) {
      std::array<float, 64> g{};
      const auto d = dirOf(layout[s][0], layout[s][1]);
      v.gains(d.data(), g);
      INFO("layout of " << layout.size() << ", loudspeaker " << s);
      CHECK(g[s] * g[s] >= 0.9f);  // the bound; VBAP gives 1 (float rounding)
      CHECK(g[s] == Approx(1.0).margin(1e-5));
    }
  }
}

TEST_CASE("VBAP: constant power, non-negative gains over the sphere") {
  std::mt19937 rng(7);
  std::normal_distribution<float> n;
  for (const Angles& layout : {k51, k714, dome()}) {
    const Vbap v(layout);
    for (int i = 0; i < 2000; ++i) {
      const float d[3] = {n(rng), n(rng), n(rng)};
      std::array<float, 64> g{};
      v.gains(d, g);
      double sum = 0;
      for (size_t s = 0; s < layout.size(); ++s) {
        CHECK(g[s] >= 0.f);
        sum += double(g[s]) * g[s];
      }
      CHECK(sum == Approx(1.0).margin(1e-5));  // Pulkki's normalisation, float rounding
    }
    // Straight down (an imaginary nadir for 7.1.4 and the dome; 5.1 is 2-D): still 1.
    std::array<float, 64> g{};
    const float down[3] = {0, 0, -1};
    v.gains(down, g);
    double sum = 0;
    for (size_t s = 0; s < layout.size(); ++s) sum += double(g[s]) * g[s];
    CHECK(sum == Approx(1.0).margin(1e-5));
  }
}

TEST_CASE("VBAP: between two loudspeakers the gains follow the tangent law") {
  // Pulkki 1997: for a pair at +-phi0 about its bisector and a source at phi from it,
  // (g1 - g2) / (g1 + g2) = tan(phi) / tan(phi0). 5.1's C (0) and L (30 degrees): bisector
  // 15 degrees, phi0 = 15; a source at 10 degrees is at phi = -5.
  const Vbap v(k51);
  std::array<float, 64> g{};
  const auto d = dirOf(10, 0);
  v.gains(d.data(), g);
  const double deg = std::numbers::pi / 180;
  CHECK((g[0] - g[2]) / (g[0] + g[2]) == Approx(std::tan(-5 * deg) / std::tan(15 * deg)).margin(1e-5));
  CHECK(g[1] == 0.f);  // R, Ls, Rs outside the pair
  CHECK(g[3] == 0.f);
  CHECK(g[4] == 0.f);
}

TEST_CASE("VBAP: NaN angles and loudspeakers within 1 degree are refused") {
  CHECK_THROWS_AS(Vbap(Angles{{30, 0}, {30.5, 0}, {-30, 0}}), std::invalid_argument);
  CHECK_THROWS_AS(Vbap(Angles{{std::nan(""), 0}, {-30, 0}}), std::invalid_argument);
  CHECK_THROWS_AS(Vbap(Angles{{0, 0}}), std::invalid_argument);
}

TEST_CASE("VBAP: a layout symmetric left to right pans mirrored directions mirrored") {
  // Oracle: symmetry. 7.1.4's four rear loudspeakers (+-135 at 0 and 30 degrees) are
  // coplanar: a hull face of four, which one diagonal alone would split unevenly (a source
  // straight behind at 15 degrees up leaned 1.6 dB to the right). Mirroring a direction in
  // the median plane (y -> -y) must swap each left loudspeaker's gain with its right one's,
  // and the gains must still point at the direction (sum g_i l_i parallel to it: VBAP's
  // definition). 4000 random directions; float rounding 1e-5.
  const Angles& layout = k714;
  const Vbap v(layout);
  auto mirrorOf = [&](size_t s) {
    for (size_t m = 0; m < layout.size(); ++m)
      if (layout[m][0] == -layout[s][0] && layout[m][1] == layout[s][1]) return m;
    return s;
  };
  std::mt19937 rng(11);
  std::normal_distribution<float> n;
  for (int i = 0; i < 4000; ++i) {
    const float d[3] = {n(rng), n(rng), n(rng)};
    const float e[3] = {d[0], -d[1], d[2]};
    std::array<float, 64> g{}, h{};
    v.gains(d, g);
    v.gains(e, h);
    std::array<double, 3> sum{};
    for (size_t s = 0; s < layout.size(); ++s) {
      INFO("direction " << d[0] << " " << d[1] << " " << d[2] << ", loudspeaker " << s);
      CHECK(g[s] == Approx(h[mirrorOf(s)]).margin(1e-5));
      const auto l = dirOf(layout[s][0], layout[s][1]);
      for (int k = 0; k < 3; ++k) sum[size_t(k)] += double(g[s]) * l[size_t(k)];
    }
    // Between the horizon and 20 degrees up only real loudspeakers' faces lie (7.1.4 closes
    // its hull with an imaginary nadir and zenith, whose gain is dropped).
    if (d[2] >= 0.f && d[2] < 0.34f * std::hypot(d[0], d[1])) {
      const double len = std::sqrt(double(d[0]) * d[0] + double(d[1]) * d[1] + double(d[2]) * d[2]);
      const double sl = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
      const double cosine = (sum[0] * d[0] + sum[1] * d[1] + sum[2] * d[2]) / (len * sl);
      CHECK(cosine == Approx(1.0).margin(1e-5));
    }
  }
  // Straight behind at 15 degrees up: left and right alike.
  std::array<float, 64> g{};
  const auto behind = dirOf(180, 15);
  v.gains(behind.data(), g);
  CHECK(g[3] == Approx(g[4]).margin(1e-6));   // +-135 at 0
  CHECK(g[9] == Approx(g[10]).margin(1e-6));  // +-135 at 30
}
