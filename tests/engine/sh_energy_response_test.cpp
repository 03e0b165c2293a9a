// Spherical-harmonic energy per bin and band (engine/sh_energy_response.h): a plane wave gives
// its energy times the SN3D table values of its direction, and the late field of a diffuse box
// has first-order components at zero within their Monte Carlo error.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "engine/sh_energy_response.h"
#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

// Oracle: AmbiX SN3D table (Nachbar et al. 2011; Zotter & Frank 2019, table 4.1) up to order 2
// for azimuth phi = 45, elevation theta = 30 degrees: Y_0 = 1, Y_1^-1 = sin phi cos theta,
// Y_1^0 = sin theta, Y_1^1 = cos phi cos theta, Y_2^-2 = sqrt(3)/2 sin 2phi cos^2 theta,
// Y_2^-1 = sqrt(3)/2 sin phi sin 2theta, Y_2^0 = (3 sin^2 theta - 1) / 2, Y_2^1 = sqrt(3)/2
// cos phi sin 2theta, Y_2^2 = sqrt(3)/2 cos 2phi cos^2 theta. Float rounding: 1e-6 relative.
TEST_CASE("SH energy: a plane wave adds its energy times Y(direction), ACN/SN3D",
          "[engine][bake]") {
  const double phi = M_PI / 4, theta = M_PI / 6, h = std::sqrt(3.0) / 2;
  const double table[9] = {1.0,
                           std::sin(phi) * std::cos(theta),
                           std::sin(theta),
                           std::cos(phi) * std::cos(theta),
                           h * std::sin(2 * phi) * std::cos(theta) * std::cos(theta),
                           h * std::sin(phi) * std::sin(2 * theta),
                           (3 * std::sin(theta) * std::sin(theta) - 1) / 2,
                           h * std::cos(phi) * std::sin(2 * theta),
                           h * std::cos(2 * phi) * std::cos(theta) * std::cos(theta)};
  // A listener facing world +z (yaw -90 degrees: its left is world +x, up world +y); the
  // wave's direction in its frame (x forward, y left, z up) is (cos t cos p, cos t sin p, sin t).
  ListenerFrame frame;
  frame.set({0, 0, 1}, {0, 1, 0});
  const glm::vec3 local{float(std::cos(theta) * std::cos(phi)),
                        float(std::cos(theta) * std::sin(phi)), float(std::sin(theta))};
  ShEnergyResponse sh(2, 0.1, 0.01, frame);
  Bands e;
  for (int b = 0; b < kNumBands; ++b) e[b] = 0.5f + 0.25f * float(b);
  sh.add(0.0234, e, frame.toWorld(local));
  REQUIRE(sh.channels() == 9);
  for (size_t k = 0; k < sh.binCount(); ++k)
    for (size_t c = 0; c < 9; ++c)
      for (int b = 0; b < kNumBands; ++b) {
        const double want = k == 2 ? table[c] * double(e[b]) : 0.0;
        CHECK(sh.bin(k)[c * kNumBands + size_t(b)] == Approx(want).epsilon(1e-6).margin(1e-7));
      }
}

// Oracle: in the late field of a closed box with fully scattering walls, arrivals come from
// every direction alike, so E[Y_1m(d)] = 0 for each first-order channel. The test sums the
// channels over 150..500 ms and the 8 bands in each of F independent frames (plain path
// tracing: frame f's rays are independent of frame g's), and compares the ratio R_m =
// sum_f X_mf / sum_f W_f (W channel 0, X channel m) with zero. Its standard error is estimated
// from the frames themselves: se = sd_f(X_mf / mean W) / sqrt(F); per arrival Var Y_1m = 1/3
// (a uniform direction's component), so se is about 1 / sqrt(3 n_eff) for n_eff effective
// arrivals, a few thousandths here. |R_m| < 4 se fails by chance with probability 6e-5 each.
// The source and listener lie in the box's mid-planes y = 1.5 and z = 3.5, so the y and z
// channels vanish by symmetry too; along x the late field has forgotten the source (the mean
// free path 4V/S = 3.5 m is crossed every 10 ms; 150 ms are 15 reflections).
TEST_CASE("SH energy: a diffuse late field has first-order components at zero",
          "[engine][bake][heavy]") {
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.1f), 1.f, {2.5f, 1.5f, 3.5f},
                                      {5.f, 1.5f, 3.5f});
  scene.propagation.estimator = Estimator::kPathTracing;
  scene.propagation.raysPerFrame = 8192;
  scene.propagation.irLength = 0.5f;
  scene.propagation.exactOrder = 0;
  Simulation sim(scene);
  sim.enableShEnergy(1, 0.01);
  const int F = 16;
  std::vector<double> W(F, 0.0);
  std::vector<std::vector<double>> X(3, std::vector<double>(F, 0.0));
  for (int f = 0; f < F; ++f) {
    sim.runFrame({5.f, 1.5f, 3.5f});
    const ShEnergyResponse& sh = sim.shEnergy(0);
    for (size_t k = 15; k < 50; ++k)
      for (int b = 0; b < kNumBands; ++b) {
        W[size_t(f)] += sh.bin(k)[b];
        for (size_t m = 0; m < 3; ++m) X[m][size_t(f)] += sh.bin(k)[(m + 1) * kNumBands + size_t(b)];
      }
  }
  double meanW = 0.0;
  for (const double w : W) meanW += w / F;
  REQUIRE(meanW > 0.0);
  for (size_t m = 0; m < 3; ++m) {
    double mean = 0.0, var = 0.0;
    for (const double x : X[m]) mean += x / meanW / F;
    for (const double x : X[m]) var += (x / meanW - mean) * (x / meanW - mean) / (F - 1);
    const double se = std::sqrt(var / F);
    INFO("channel " << m + 1 << ": R = " << mean << ", se = " << se);
    CHECK(se < 0.02);  // the test resolves a first-order component of 0.08 (4 se)
    CHECK(std::abs(mean) < 4.0 * se);
  }
}
