// Exact early specular paths never count a path twice, from the first frame on: a render with
// exact paths (exact_order 3) reads the same energy (G) and early-to-late ratio (C80) as the
// same render without them (exact_order 0, where every path is Monte Carlo), after 1, 2 and 30
// frames, for plain path tracing and the DPC, in a specular and in a diffuse room. The oracle
// is the exact_order 0 render of independent seeds: the two must agree within the Monte Carlo
// error measured from the seeds' spread. Before the exclusion was decided by each hit's own
// sequence, the first frame counted the early specular energy twice (G +1.7 dB, C80 +1.9 dB in
// a one-frame render of a specular room). The same with a free-standing panel hung under the
// ceiling, whose first-order exact path takes the Kirchhoff integral and the rays Rindel's share.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "engine/simulation.h"
#include "engine/specular_paths.h"
#include "testing/kirchhoff.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using namespace dpc;

namespace {

constexpr int kBand = 4;  // 1 kHz
constexpr int kSeeds = 8;

struct Reading {
  double total = 0.0;  ///< the response's energy in one band, exact paths included (no direct)
  double early = 0.0;  ///< the part before 80 ms
};

/// A 1 x 1 m panel (both windings) 0.5 m under the ceiling of room() below, at the specular
/// point of its source and listener: struck 72 degrees off its normal, a small share of its
/// Fresnel zone (the Kirchhoff integral -22 dB at 125 Hz, -16 dB at 250 Hz, -6 dB at 1 kHz).
const test::Rect kPanel{{4.13, 2.5, 3.08}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}};

SceneDesc room(float scattering, Estimator estimator, int exactOrder, bool panel = false) {
  SceneDesc s = test::makeShoebox({10, 3, 7}, Bands(0.1f), scattering, {2, 1.5f, 2}, {7, 1.6f, 5});
  if (panel)
    test::addPanel(s.mesh, glm::vec3(kPanel.o), glm::vec3(kPanel.u), glm::vec3(kPanel.v), 0);
  s.propagation.raysPerFrame = 2048;
  s.propagation.estimator = estimator;
  s.propagation.exactOrder = exactOrder;
  s.propagation.irLength = 0.6f;
  return s;
}

/// The response after `frames` frames of seed `seed`: the estimator's bins plus the exact
/// paths at their delays (what --er-out writes), summed in `band`.
Reading render(SceneDesc scene, uint64_t seed, int frames, int band) {
  scene.propagation.seed = seed;
  Simulation sim(scene);
  for (int f = 0; f < frames; ++f) sim.runFrame(scene.listeners[0].position);
  EnergyResponse e = sim.result(0).energy;
  addSpecularPaths(sim.specularPaths(0), e);
  Reading r;
  for (size_t k = 0; k < e.binCount(); ++k) {
    const double v = e.bins()[k][band];
    r.total += v;
    if (double(k) * e.binSeconds() < 0.080) r.early += v;
  }
  return r;
}

struct Stats {
  double g = 0.0, gError = 0.0;      ///< mean total energy and its standard error
  double c80 = 0.0, c80Error = 0.0;  ///< mean early / late ratio and its standard error
};

Stats over(const SceneDesc& scene, uint64_t firstSeed, int frames, int band = kBand) {
  std::vector<double> totals, ratios;
  for (int i = 0; i < kSeeds; ++i) {
    const Reading r = render(scene, firstSeed + uint64_t(i), frames, band);
    totals.push_back(r.total);
    ratios.push_back(r.early / (r.total - r.early));
  }
  Stats s;
  std::tie(s.g, s.gError) = test::meanAndStandardError(totals);
  std::tie(s.c80, s.c80Error) = test::meanAndStandardError(ratios);
  return s;
}

}  // namespace

TEST_CASE("Exact paths and their rays' hits never both count, from the first frame on",
          "[specular][balance][statistics]") {
  for (const float scattering : {0.1f, 0.6f})
    for (const Estimator estimator : {Estimator::kPathTracing, Estimator::kDpc})
      for (const int frames : {1, 2, 30}) {
        if (estimator == Estimator::kPathTracing && frames == 30) continue;  // = frame 1's
        const Stats exact = over(room(scattering, estimator, 3), 100, frames);
        const Stats plain = over(room(scattering, estimator, 0), 200, frames);
        INFO("scattering " << scattering << ", "
                           << (estimator == Estimator::kDpc ? "DPC" : "path tracing") << ", "
                           << frames << " frame(s): G " << 10 * std::log10(exact.g / plain.g)
                           << " dB, C80 " << 10 * std::log10(exact.c80 / plain.c80) << " dB");
        // Independent seeds: the difference's standard error is the two errors combined; 4 of
        // them bound a chance failure below 1e-4 per comparison. Counting the early specular
        // energy twice moves G by +1.7 dB (+48 %) and C80 by +1.9 dB in the specular room, many
        // standard errors even at 8 seeds of 2048 rays (the G differences of a correct render
        // read within 0.07 dB, 1.6 %, at 12 seeds of 4096).
        CHECK(std::abs(exact.g - plain.g) < 4.0 * std::hypot(exact.gError, plain.gError));
        CHECK(std::abs(exact.c80 - plain.c80) < 4.0 * std::hypot(exact.c80Error, plain.c80Error));
      }
}

TEST_CASE("Exact paths and their rays' hits balance off a panel hung under the ceiling",
          "[specular][balance][statistics]") {
  // The panel stands free; the ceiling 0.5 m behind it is within an eighth of a wavelength at
  // 63 Hz only, where panel and ceiling reflect together. Above, the first-order exact path
  // carries the panel's own Kirchhoff share and the rays it replaces Rindel's (within 0.3 dB
  // of it at 125 and 250 Hz here, 1.8 dB below it at 1 kHz, where the panel's reflection is a
  // tenth of a per cent of the response: below the Monte Carlo error). Before the exact share
  // stopped at the first band the ceiling made whole, the exact path carried the whole
  // reflection at every band and the DPC after 30 frames read G +0.10 dB (4.7 standard
  // errors) and C80 +0.25 dB at 250 Hz with exact paths on.
  for (const Estimator estimator : {Estimator::kPathTracing, Estimator::kDpc})
    for (const int band : {1, 2, 4})
      for (const int frames : {1, 30}) {
        if (estimator == Estimator::kPathTracing && frames == 30) continue;  // = frame 1's
        const Stats exact = over(room(0.1f, estimator, 3, true), 100, frames, band);
        const Stats plain = over(room(0.1f, estimator, 0, true), 200, frames, band);
        INFO((estimator == Estimator::kDpc ? "DPC" : "path tracing")
             << ", " << frames << " frame(s), band " << band << ": G "
             << 10 * std::log10(exact.g / plain.g) << " dB, C80 "
             << 10 * std::log10(exact.c80 / plain.c80) << " dB");
        // As above: 4 standard errors of the difference.
        CHECK(std::abs(exact.g - plain.g) < 4.0 * std::hypot(exact.gError, plain.gError));
        CHECK(std::abs(exact.c80 - plain.c80) < 4.0 * std::hypot(exact.c80Error, plain.c80Error));
      }
}

TEST_CASE(
    "A panel's first-order exact path is its own Kirchhoff share above the bands a "
    "surface behind it joins",
    "[specular]") {
  // The independent oracle: Kirchhoff's integral over the panel alone (testing/kirchhoff.h,
  // the octave's mean of 16 frequencies). The engine integrates the panel's zone with a taper
  // over its first four zones, which the oracle does not: within 1 dB from 125 Hz to 1 kHz,
  // where the share is -22 to -6 dB. At 63 Hz the ceiling, 0.5 m behind, lies within an eighth
  // of the wavelength (0.68 m) and panel and ceiling reflect whole together (0 dB). Before, that
  // whole 63 Hz band ended the integration and every band read 0 dB.
  SceneDesc s = room(0.1f, Estimator::kPathTracing, 1, true);
  s.propagation.airAbsorption = false;
  Simulation sim(s);
  sim.runFrame(s.listeners[0].position);
  const glm::dvec3 src(s.sources[0].position), lis(s.listeners[0].position);
  const SpecularPath* panel = nullptr;
  for (const SpecularPath& p : sim.specularPaths(0))
    if (p.order == 1 && p.triangles[0] >= 12) panel = &p;  // the room's 12 triangles first
  REQUIRE(panel != nullptr);
  // The path's intensity over the image source's with the panel's (1 - alpha)(1 - s).
  const double image = 0.9 * 0.9 / (4.0 * std::numbers::pi * panel->length * panel->length);
  for (int b = 0; b <= 4; ++b) {
    const double engine = 10.0 * std::log10(double(panel->intensity[b]) / image);
    const double oracle = b == 0 ? 0.0 : test::kirchhoffBandDb({kPanel}, src, lis, b, 200, 200);
    std::printf("panel's first-order share, band %d: engine %.2f dB, oracle %.2f dB\n", b, engine,
                oracle);
    CHECK(std::abs(engine - oracle) < 1.0);
  }
}
