#include "engine/propagation.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <numbers>

#include "engine/embree_tracer.h"
#include "engine/simulation.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using namespace dpc;

using test::identical;

namespace {

/// The 10 x 3 x 7 m shoebox of these tests: source at (2, 1.5, 2), listener at (7, 1.6, 5).
SceneDesc shoebox(float absorption, float scattering) {
  return test::makeShoebox({10, 3, 7}, Bands(absorption), scattering, {2, 1.5f, 2}, {7, 1.6f, 5});
}

/// Default settings but `rays` rays per source and frame, reflection order `maxOrder`, `seed`.
PropagationSettings seededSettings(int rays, int maxOrder, uint64_t seed) {
  PropagationSettings ps;
  ps.raysPerFrame = rays;
  ps.maxOrder = maxOrder;
  ps.seed = seed;
  return ps;
}

}  // namespace

// docs/design.md oracle: the energy of order-0 rays through the listener sphere estimates the
// direct intensity 1/(4 pi r^2) (times air attenuation).
TEST_CASE("Order-0 energy through the listener sphere is 1/(4 pi r^2)", "[calibration]") {
  // A huge box so that no reflection comes back within max order 0.
  SceneDesc scene =
      test::makeShoebox({200, 200, 200}, Bands(1.f), 1.f, {100, 100, 100}, {104, 101, 102}, 0.5f);
  PropagationSettings ps;
  ps.raysPerFrame = 2000000;
  ps.maxOrder = 0;
  ps.estimator = Estimator::kPathTracing;
  Simulation sim(scene, ps);
  FrameInputs in = sim.inputsAt(scene.listeners[0].position);
  in.includeDirectRays = true;
  sim.runFrame(in);
  const double r = std::sqrt(16.0 + 1.0 + 4.0);
  const double R = 0.5;
  const Bands total = sim.result(0).energy.total();
  const Bands expected = sim.result(0).direct.intensity;  // 1/(4 pi r^2) e^{-m r}, analytic
  REQUIRE(sim.result(0).direct.visible);
  CHECK(expected[4] == Approx(std::exp(-sim.propagator().airAttenuationPerMetre()[4] * r) /
                              (4 * std::numbers::pi * r * r)));
  // Hits are binomial with p = (1 - sqrt(1 - R^2/r^2)) / 2 (the sphere's solid angle share);
  // the estimate's mean is p / (pi R^2), which exceeds 1/(4 pi r^2) by the factor
  // 2 r^2 (1 - sqrt(1 - R^2/r^2)) / R^2 (+0.3 % here); relative sigma = sqrt((1-p)/(N p)).
  const double p = (1 - std::sqrt(1 - R * R / (r * r))) / 2;
  const double geometric = 2 * r * r * (1 - std::sqrt(1 - R * R / (r * r))) / (R * R);
  const double sigma = std::sqrt((1 - p) / (ps.raysPerFrame * p));
  for (int b = 0; b < kNumBands; ++b) {
    const double ratio = total[b] / (expected[b] * geometric);
    INFO("band " << b << ": estimate / analytic = " << ratio << ", sigma = " << sigma);
    CHECK(std::abs(ratio - 1.0) < 4 * sigma);
  }
}

TEST_CASE("tau = 0 DPC reproduces plain path tracing exactly, frame after frame", "[dpc][packet]") {
  SceneDesc scene = shoebox(0.2f, 0.7f);
  PropagationSettings ps = seededSettings(2000, 30, 42);
  ps.cacheTau = 0.f;
  for (TraceMode mode : {TraceMode::kPacket16, TraceMode::kScalar})
    for (DpcWeighting w : {DpcWeighting::kSeed, DpcWeighting::kEma, DpcWeighting::kWindow}) {
      PropagationSettings dpcSettings = ps, ptSettings = ps;
      dpcSettings.estimator = Estimator::kDpc;
      dpcSettings.dpcWeighting = w;
      ptSettings.estimator = Estimator::kPathTracing;
      Simulation dpcSim(scene, dpcSettings, {mode, {}}), ptSim(scene, ptSettings, {mode, {}});
      for (int f = 0; f < 5; ++f) {
        const glm::vec3 listener(7.f - 0.3f * f, 1.6f, 5.f);  // moving: nothing may carry over
        dpcSim.runFrame(listener);
        ptSim.runFrame(listener);
        REQUIRE(dpcSim.result(0).trace.listenerHits > 100);
        REQUIRE(identical(dpcSim.result(0).energy, ptSim.result(0).energy));
      }
    }
}

TEST_CASE("A frame is bit-identical for a seed whatever the thread count", "[determinism]") {
  SceneDesc scene = shoebox(0.1f, 0.5f);
  PropagationSettings ps = seededSettings(3000, 40, 7);
  ps.threads = 1;
  Simulation one(scene, ps);
  ps.threads = 2;
  Simulation two(scene, ps);
  ps.seed = 8;
  Simulation other(scene, ps);
  for (int f = 0; f < 3; ++f) {
    one.runFrame(scene.listeners[0].position);
    two.runFrame(scene.listeners[0].position);
    other.runFrame(scene.listeners[0].position);
    REQUIRE(identical(one.result(0).energy, two.result(0).energy));
    REQUIRE_FALSE(identical(one.result(0).energy, other.result(0).energy));
  }
}

TEST_CASE("Direct sound is blocked by a wall and respects the speed of sound", "[direct]") {
  SceneDesc scene = shoebox(0.1f, 0.5f);
  Geometry g(scene.mesh, scene.materials, 0.5f);
  EmbreeTracer tracer(scene.mesh);
  PropagationSettings ps;
  Propagator prop(g, tracer, ps);
  const DirectSound inside = prop.directSound({2, 1.5f, 2}, {{7, 1.5f, 2}, 0.5f});
  CHECK(inside.visible);
  CHECK(inside.delaySeconds == Approx(5.0 / ps.speedOfSound));
  const DirectSound outside = prop.directSound({2, 1.5f, 2}, {{12, 1.5f, 2}, 0.5f});
  CHECK_FALSE(outside.visible);
  CHECK(outside.intensity.max() == 0.f);
}

// Nothing is lost silently: a ray the reflection order bound ends adds the energy it still
// carries to TraceStats::maxOrderEnergy. Oracle: in a closed box of one absorption a and no
// air, every ray meets its (N+1)-th wall with (1 - a)^N of its energy, whatever path it took
// (reflections scale energy alike, specular or scattered), so the bound's total over R rays is
// R (1 - a)^N in every band; exact but for float sums (relative 1e-4 allowed). With a bound
// beyond where Russian roulette ends every ray (0.8^k < 1e-6 from k = 62), nothing is cut.
TEST_CASE("Rays the order bound ends report the energy they still carried", "[calibration]") {
  const SceneDesc scene = shoebox(0.2f, 0.5f);
  for (const int maxOrder : {4, 10, 300}) {
    PropagationSettings ps = seededSettings(8000, maxOrder, 5);  // 1000 rays per band
    ps.airAbsorption = false;
    ps.exactOrder = std::min(ps.exactOrder, maxOrder);
    Simulation sim(scene, ps);
    sim.runFrame(sim.inputsAt(scene.listeners[0].position));
    const TraceStats& trace = sim.result(0).trace;
    const double expected = maxOrder > 100 ? 0.0 : std::pow(0.8, maxOrder);
    for (int b = 0; b < kNumBands; ++b) {
      const double share = double(trace.maxOrderEnergy[b]) / double(trace.rays);
      INFO("max order " << maxOrder << ", band " << b << ": share " << share << " expected "
                        << expected);
      CHECK(share == Approx(expected).epsilon(1e-4).margin(1e-12));
    }
  }
}
