// Specular shoebox against an exact image-source energy reference (validation suite).
//
// A rectangular room with scattering 0 is exactly the image-source lattice (J. B. Allen &
// D. A. Berkley, "Image method for efficiently simulating small-room acoustics", JASA 65,
// 1979): image (i, j, k) of the source lies at (2 i Lx +- xs, ...), its energy at the listener
// is (1 - alpha)^n / (4 pi d^2), n the number of wall reflections. The reference below is
// written from that definition; the tracer's band energy response (plain path tracing, many
// frames) must match it per 20 ms window within Monte Carlo error.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "engine/simulation.h"
#include "engine/specular_paths.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

/// Energy per bin (binSeconds) of every image up to `maxTime`, relative to source power.
std::vector<double> imageSourceEnergy(glm::vec3 room, glm::vec3 src, glm::vec3 lis, double alpha,
                                      double c, double binSeconds, double maxTime) {
  std::vector<double> e(size_t(maxTime / binSeconds) + 1, 0.0);
  const int reach = int(std::ceil(maxTime * c / (2.0 * std::min({room.x, room.y, room.z})))) + 1;
  for (int i = -reach; i <= reach; ++i)
    for (int j = -reach; j <= reach; ++j)
      for (int k = -reach; k <= reach; ++k)
        for (int m = 0; m < 8; ++m) {
          // Mirror flag per axis: position 2 i L + s or 2 i L - s; reflections |2i| or |2i-1|.
          const int fx = m & 1, fy = (m >> 1) & 1, fz = (m >> 2) & 1;
          const double x = 2.0 * i * room.x + (fx ? -src.x : src.x);
          const double y = 2.0 * j * room.y + (fy ? -src.y : src.y);
          const double z = 2.0 * k * room.z + (fz ? -src.z : src.z);
          const int n = std::abs(2 * i - fx) + std::abs(2 * j - fy) + std::abs(2 * k - fz);
          if (n == 0) continue;  // the direct sound is analytic in dpc, not traced
          const double d = std::sqrt((x - lis.x) * (x - lis.x) + (y - lis.y) * (y - lis.y) +
                                     (z - lis.z) * (z - lis.z));
          const double t = d / c;
          if (t >= maxTime) continue;
          e[size_t(t / binSeconds)] += std::pow(1.0 - alpha, n) / (4.0 * std::numbers::pi * d * d);
        }
  return e;
}

/// Mean and standard error of the mean, over frames, of one band's energy per window.
struct WindowStats {
  std::vector<double> mean, standardError;
};

/// Runs `frames` frames of plain path tracing and sums band `band` of each frame's energy
/// response into windows of binSeconds up to maxTime.
WindowStats windowEnergies(const SceneDesc& scene, glm::vec3 listener, int band, int frames,
                           double binSeconds, double maxTime) {
  Simulation sim(scene);
  const size_t windows = size_t(maxTime / binSeconds) + 1;
  std::vector<std::vector<double>> perFrame;
  for (int f = 0; f < frames; ++f) {
    sim.runFrame(listener);
    // The whole response: the estimator's, plus the exact early paths it leaves out.
    EnergyResponse er = sim.result(0).energy;
    addSpecularPaths(sim.specularPaths(0), er);
    std::vector<double> e(windows, 0.0);
    for (size_t k = 0; k < er.binCount(); ++k) {
      const double t = (double(k) + 0.5) * er.binSeconds();
      if (t < maxTime) e[size_t(t / binSeconds)] += er.bins()[k][band];
    }
    perFrame.push_back(e);
  }
  WindowStats w;
  for (size_t i = 0; i < windows; ++i) {
    double m = 0, s2 = 0;
    for (const auto& e : perFrame) m += e[i];
    m /= frames;
    for (const auto& e : perFrame) s2 += (e[i] - m) * (e[i] - m);
    w.mean.push_back(m);
    w.standardError.push_back(std::sqrt(s2 / (frames - 1) / frames));
  }
  return w;
}

/// The specular shoebox of both tests: 6 x 3 x 4 m, absorption alpha, no air, R = 0.3 m, plain
/// path tracing up to order 100 (0.5 s holds about 64 reflections here), no roulette.
SceneDesc specularTestRoom(glm::vec3 room, glm::vec3 src, glm::vec3 lis, double alpha, double c,
                           int rays, double maxTime) {
  SceneDesc scene = test::makeShoebox(room, Bands(float(alpha)), 0.f, src, lis, 0.3f);
  scene.propagation.estimator = Estimator::kPathTracing;
  scene.propagation.airAbsorption = false;
  scene.propagation.raysPerFrame = rays;
  scene.propagation.maxOrder = 100;
  scene.propagation.rouletteThreshold = 0.f;
  scene.propagation.speedOfSound = float(c);
  scene.propagation.irLength = float(maxTime + 0.05);
  return scene;
}

}  // namespace

TEST_CASE("Specular shoebox: energy per 20 ms matches exact image sources",
          "[validation][statistics]") {
  const glm::vec3 room{6.f, 3.f, 4.f}, src{1.5f, 1.2f, 1.3f}, lis{4.2f, 1.7f, 2.6f};
  const double alpha = 0.2, c = 343.0, bin = 0.02, maxTime = 0.2;
  const SceneDesc scene = specularTestRoom(room, src, lis, alpha, c, 20000, maxTime);
  const WindowStats w = windowEnergies(scene, lis, 4, 20, bin, maxTime);
  const std::vector<double> ref = imageSourceEnergy(room, src, lis, alpha, c, bin, maxTime);
  // From 20 ms on (the first window holds only a few images: the listener sphere's radius
  // smears each arrival by +-R/c = 0.9 ms and first-order hits are few) to 200 ms.
  for (size_t i = 1; i + 1 < ref.size(); ++i) {
    const double m = w.mean[i], se = w.standardError[i];
    std::printf("image sources: %3.0f-%3.0f ms  traced %.4e +- %.1e  exact %.4e  (%+.1f %%)\n",
                i * bin * 1e3, (i + 1) * bin * 1e3, m, se, ref[i], 100 * (m / ref[i] - 1));
    // 4 standard errors of the 20-frame mean, plus 3 % for arrivals near a window edge that
    // the sphere's +-R/c smear moves across it.
    CHECK(std::abs(m - ref[i]) < 4 * se + 0.03 * ref[i]);
  }
}

TEST_CASE("Scattering per band: each band follows its own coefficient",
          "[validation][statistics]") {
  // Scattering 0 in the four low bands and 1 in the four high ones. The 63 Hz band must still
  // be the exact image-source response, and the 8 kHz band must be a fully diffuse room's
  // (the same room traced with scattering 1 in every band), each within Monte Carlo error.
  const glm::vec3 room{6.f, 3.f, 4.f}, src{1.5f, 1.2f, 1.3f}, lis{4.2f, 1.7f, 2.6f};
  // 50 ms windows to 0.5 s: late enough for specular and diffuse decays to part.
  const double alpha = 0.2, c = 343.0, bin = 0.05, maxTime = 0.5;
  const int frames = 20;
  SceneDesc mixed = specularTestRoom(room, src, lis, alpha, c, 40000, maxTime);
  for (int b = kNumBands / 2; b < kNumBands; ++b) mixed.materials[0].scattering[b] = 1.f;
  SceneDesc diffuse = specularTestRoom(room, src, lis, alpha, c, 20000, maxTime);
  diffuse.materials[0].scattering = Bands(1.f);
  const WindowStats low = windowEnergies(mixed, lis, 0, frames, bin, maxTime);
  const WindowStats high = windowEnergies(mixed, lis, kNumBands - 1, frames, bin, maxTime);
  const WindowStats diffuseHigh = windowEnergies(diffuse, lis, kNumBands - 1, frames, bin, maxTime);
  const std::vector<double> ref = imageSourceEnergy(room, src, lis, alpha, c, bin, maxTime);
  int distinct = 0;
  for (size_t i = 1; i + 1 < ref.size(); ++i) {
    std::printf("per-band scattering: %3.0f-%3.0f ms  63 Hz %.4e +- %.1e (image sources %.4e)  "
                "8 kHz %.4e +- %.1e (diffuse %.4e +- %.1e)\n",
                i * bin * 1e3, (i + 1) * bin * 1e3, low.mean[i], low.standardError[i], ref[i],
                high.mean[i], high.standardError[i], diffuseHigh.mean[i],
                diffuseHigh.standardError[i]);
    // As in the test above: 4 standard errors plus 3 % for the sphere's smear at window edges.
    CHECK(std::abs(low.mean[i] - ref[i]) < 4 * low.standardError[i] + 0.03 * ref[i]);
    // Two independent estimates: 4 combined standard errors.
    const double se = std::hypot(high.standardError[i], diffuseHigh.standardError[i]);
    CHECK(std::abs(high.mean[i] - diffuseHigh.mean[i]) < 4 * se);
    // The two references must differ where it matters, or the test could not fail.
    if (std::abs(diffuseHigh.mean[i] - ref[i]) > 4 * se + 0.03 * ref[i]) ++distinct;
  }
  CHECK(distinct >= 2);
}
