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
#include "test_scenes.h"

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

}  // namespace

TEST_CASE("Specular shoebox: energy per 20 ms matches exact image sources", "[validation]") {
  const glm::vec3 room{6.f, 3.f, 4.f}, src{1.5f, 1.2f, 1.3f}, lis{4.2f, 1.7f, 2.6f};
  const double alpha = 0.2, c = 343.0, bin = 0.02, maxTime = 0.2;
  SceneDesc scene = test::makeShoebox(room, Bands(float(alpha)), 0.f, src, lis, 0.3f);
  scene.propagation.estimator = Estimator::kPathTracing;
  scene.propagation.airAbsorption = false;
  scene.propagation.raysPerFrame = 20000;
  scene.propagation.maxOrder = 100;
  scene.propagation.rouletteThreshold = 0.f;
  scene.propagation.speedOfSound = float(c);
  scene.propagation.irLength = 0.25f;
  Simulation sim(scene);
  const int frames = 20;
  std::vector<std::vector<double>> perFrame;
  for (int f = 0; f < frames; ++f) {
    sim.runFrame(lis);
    const EnergyResponse& er = sim.result(0).energy;
    std::vector<double> e(size_t(maxTime / bin) + 1, 0.0);
    for (size_t k = 0; k < er.binCount(); ++k) {
      const double t = (double(k) + 0.5) * er.binSeconds();
      if (t < maxTime) e[size_t(t / bin)] += er.bins()[k][4];
    }
    perFrame.push_back(e);
  }
  const std::vector<double> ref = imageSourceEnergy(room, src, lis, alpha, c, bin, maxTime);
  // From 20 ms on (the first window holds only a few images: the listener sphere's radius
  // smears each arrival by +-R/c = 0.9 ms and first-order hits are few) to 200 ms.
  for (size_t w = 1; w + 1 < ref.size(); ++w) {
    double m = 0, s2 = 0;
    for (const auto& e : perFrame) m += e[w];
    m /= frames;
    for (const auto& e : perFrame) s2 += (e[w] - m) * (e[w] - m);
    const double se = std::sqrt(s2 / (frames - 1) / frames);
    std::printf("image sources: %3.0f-%3.0f ms  traced %.4e +- %.1e  exact %.4e  (%+.1f %%)\n",
                w * bin * 1e3, (w + 1) * bin * 1e3, m, se, ref[w], 100 * (m / ref[w] - 1));
    // 4 standard errors of the 20-frame mean, plus 3 % for arrivals near a window edge that
    // the sphere's +-R/c smear moves across it.
    CHECK(std::abs(m - ref[w]) < 4 * se + 0.03 * ref[w]);
  }
}
