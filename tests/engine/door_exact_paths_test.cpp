// Exact specular paths (engine/specular_paths.h) and a closed door. The two rooms of
// tests/engine/door_scenes.h are joined only by the doorway; with its leaf shut, the only ways
// between them are the gaps round the leaf (5 to 20 mm). The oracle is geometry, not the code
// under test: every path from the source's room to the listener's crosses the partition, so
// with the leaf shut each exact path would pass through a gap. A gap that narrow lies far
// inside any such path's first Fresnel zone (sqrt(lambda d) is 0.2 m at 8 kHz over 1 m), where
// the image construction's free zone does not hold: what passes is the slit's, which the
// direct sound's diffraction carries. So no exact path may exist, and the response's total
// energy with the leaf shut stays below the open doorway's in every band. Before, a reflection
// off a jamb's reveal inside the gap was a valid image path at the full 1/(4 pi d^2): here 1
// and 6 exact paths through the 10 and 20 mm gaps, the 20 mm door's total −7.5 dB re open
// instead of −15 (a held-out door with the listener in line with its gap read within 2 dB of
// the open doorway, above it at 63 Hz).
#include <catch2/catch.hpp>
#include <cstdio>
#include <vector>

#include "engine/simulation.h"
#include "tests/engine/door_scenes.h"

using namespace dpc;
using namespace dpc::door_test;

namespace {

constexpr int kFrames = 12;

/// The exact paths from the source to the listener after kFrames frames, and the last frame's
/// total energy per band: the estimator's response (without the hits the exact paths replace),
/// the exact paths and the direct sound (with its diffraction through the gaps).
struct Run {
  std::vector<SpecularPath> paths;
  Bands total{0.f};
};

Run run(SceneDesc scene) {
  scene.propagation.exactOrder = 3;
  scene.propagation.raysPerFrame = 8192;
  Simulation sim(scene);
  FrameInputs in = sim.inputsAt(kListener, {kSource});
  Run r;
  for (int f = 0; f < kFrames; ++f) sim.runFrame(in);
  r.paths = sim.specularPaths(0, 0);
  r.total = sim.result(0).energy.total() + sim.result(0).direct.intensity;
  for (const SpecularPath& p : r.paths) r.total += p.intensity;
  return r;
}

}  // namespace

TEST_CASE("Exact paths: a closed door's gaps pass none, and closed stays below open",
          "[specular][door][heavy]") {
  constexpr float kWall = 0.1f, kThickness = 0.04f;
  const Run open = run(thickDoorwayScene(kWall, false));
  // The control: through the open doorway the rays propose paths and the construction finds
  // them (the direct line and reflections off the floor, the ceiling and the side walls).
  REQUIRE(open.paths.size() >= 4);
  for (float gap : {0.005f, 0.01f, 0.02f}) {
    const Run shut = run(recessedLeafScene(kWall, gap, kThickness, 6.f + 0.5f * kWall));
    std::printf("gap %2.0f mm: %zu exact paths (open %zu); total energy re open (dB):",
                1e3 * double(gap), shut.paths.size(), open.paths.size());
    for (size_t b = 0; b < kNumBands; ++b)
      std::printf(" %+.1f", 10.0 * std::log10(double(shut.total[b]) / double(open.total[b])));
    std::printf("\n");
    CHECK(shut.paths.empty());
    // Monte Carlo error of the totals: 8192 rays a frame over the cache's window, the closed
    // total a few percent of the open one; a 10 % margin lies far beyond it.
    for (size_t b = 0; b < kNumBands; ++b) CHECK(shut.total[b] < 1.1f * open.total[b]);
  }
}

TEST_CASE("Exact paths: the hits of a path refused through a gap are left to the slit",
          "[specular][door]") {
  // A wall standing alone with its doorway shut by a 4 cm box leaf with gaps of 5-20 mm all
  // round, source and listener 2 m before and behind it on the axis, scattering 0 and one
  // reflection at most: every hit samples a first-order sequence the exact paths know. The only
  // ways through are the gaps, and the only first-order one is a reflection off the jamb's
  // reveal inside a side gap, which reaches every point of the listener's sphere through the
  // gap; that sequence is refused (above): what goes straight through a gap is the slit's
  // transmission in the direct sound. Its hits go with it: a beam a gap wide, far narrower than
  // its Fresnel zone, would count that transmission again, flat in frequency (in a held-out
  // sweep as much as the slit's own level, changing by 8 dB from frame to frame). Nothing else
  // arrives within 3 ms of the direct sound (the wall's rims are 30 m away). Higher orders
  // inside a gap (leaf to jamb and back) whose path to the sphere's centre does not exist keep
  // their hits (docs/estimators.md).
  const glm::vec3 source{-2.f, 1.05f, 0.f}, listener{2.f, 1.05f, 0.f};
  for (float gap : {0.005f, 0.01f, 0.02f}) {
    SceneDesc scene = doorScene(0.f, Leaf::kNone);
    scene.mesh = Mesh{};
    addFreeWallDoorway(scene.mesh, 0.1f, true);
    test::addSolidBox(scene.mesh, {-0.02f, gap, gap - 0.45f}, {0.02f, 2.1f - gap, 0.45f - gap}, 0);
    for (Material& m : scene.materials) m.scattering = Bands(0.f);
    scene.sources[0].position = source;
    scene.listeners[0].radius = 0.3f;
    scene.propagation.exactOrder = 1;
    scene.propagation.maxOrder = 1;
    scene.propagation.raysPerFrame = 65536;
    Simulation sim(scene);
    const double direct = double(glm::distance(source, listener)) / kC;
    double early = 0.0;
    for (int f = 0; f < 4; ++f) {
      sim.runFrame(listener);
      const EnergyResponse& er = sim.result(0).energy;
      for (size_t k = 0; k < er.binCount(); ++k) {
        const double t = double(k) * er.binSeconds();
        if (t + er.binSeconds() > direct && t < direct + 3e-3) early += er.bins()[k].max();
      }
    }
    std::printf("free wall, gap %2.0f mm: hits within 3 ms of the direct sound %.3e\n",
                1e3 * double(gap), early);
    CHECK(early == 0.0);
  }
}
