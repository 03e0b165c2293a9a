// The parameter map against diffuse-field theory in a shoebox. G follows Barron's revised
// theory (M. Barron, L.-J. Lee, "Energy relations in concert auditoriums I", JASA 84, 618-628,
// 1988), the classical diffuse field (reverberant intensity 4/A per unit power, Eyring's A)
// with the reverberant energy decaying from the direct sound's arrival on:
//   G(r) = 10 log10( 100 / r^2 + (4 pi 100) (4 / A) exp(-13.8 r / (c T)) ) dB,
// T Eyring's reverberation time and A = 0.161 V / T (Sabine's constant at c, eyringT60). T30 is
// the same at every probe.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "bake/probe_bake.h"
#include "testing/test_scenes.h"

using namespace dpc;
using namespace dpc::bake;

namespace {

constexpr double kAlpha = 0.2;
const glm::vec3 kSize(10.f, 3.f, 7.f);
const glm::vec3 kSource(2.f, 1.5f, 3.5f);

constexpr double kC = 343.0;  ///< m/s, the scene's default speed of sound

double theoryG(double r) {
  const double volume = double(kSize.x) * kSize.y * kSize.z;
  const double t = test::eyringT60(kSize, kAlpha, kC);
  const double area = 24.0 * std::log(10.0) / kC * volume / t;  // A = (24 ln10 / c) V / T
  const double reverberant = 4.0 / area * std::exp(-13.8155 * r / (kC * t));
  return 10.0 * std::log10((1.0 / (4.0 * std::numbers::pi * r * r) + reverberant) * 4.0 *
                           std::numbers::pi * 100.0);
}

/// Parameter k of the 1 kHz band (index 4) of source 0 (every band carries the source's full
/// power: the broadband row, their sum, is 9 dB higher).
double band1k(const std::vector<float>& v, int k) { return v[size_t(4 * kParameters + k)]; }

}  // namespace

TEST_CASE("Map: G falls with distance as diffuse-field theory predicts and T30 is uniform",
          "[bake][map][statistics]") {
  SceneDesc scene = test::makeShoebox(kSize, Bands(float(kAlpha)), 1.0f, kSource, kSource);
  scene.propagation.airAbsorption = false;
  scene.propagation.diffraction = false;
  scene.propagation.maxOrder = 400;
  BakeSettings settings;
  settings.rays = 8000;
  settings.frames = 8;
  settings.irLength = 1.5;
  std::vector<double> t30, ci;
  size_t probe = 0;
  for (const double r : {1.5, 2.5, 4.0, 5.5, 7.0}) {
    const glm::vec3 at = kSource + glm::vec3(float(r), 0.f, 0.f);
    const ProbeResult res = bakeProbe(scene, settings, probe++, at);
    const double g = band1k(res.parameters, 6);
    INFO("r = " << r << " m: G " << g << " dB, theory " << theoryG(r) << " dB, CI "
                << band1k(res.parametersCi, 6));
    // 1 dB: the diffuse-field model's own error in a 10 x 3 x 7 m room of uniform a = 0.2
    // with full scattering (the target) dominates the Monte Carlo interval (< 0.3 dB).
    CHECK(std::abs(g - theoryG(r)) < 1.0);
    t30.push_back(band1k(res.parameters, 1));
    ci.push_back(band1k(res.parametersCi, 1));
  }
  double mean = 0.0;
  for (const double t : t30) mean += t / double(t30.size());
  for (size_t i = 0; i < t30.size(); ++i) {
    INFO("probe " << i << ": T30 " << t30[i] << " s +- " << ci[i] << ", mean " << mean);
    // Uniform within Monte Carlo error: each probe within 3 of its 95 % half-widths (plus the
    // mean's own share) of the mean; a probe-dependent T30 beyond the noise fails.
    CHECK(std::abs(t30[i] - mean) < 3.0 * ci[i] + 0.01 * mean);
  }
}
