// Simulation::restart: a simulation restarted with a seed continues exactly as a fresh one
// constructed with that seed, for both estimators (the DPC's caches and the frame count are
// reset), whatever it ran before.
#include <catch2/catch.hpp>

#include "engine/simulation.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using namespace dpc;

TEST_CASE("Simulation restart equals a fresh simulation of that seed", "[engine]") {
  for (const Estimator estimator : {Estimator::kDpc, Estimator::kPathTracing}) {
    SceneDesc scene = test::makeShoebox({6.f, 3.f, 4.f}, Bands(0.2f), 0.5f, {1.f, 1.5f, 1.f},
                                        {4.f, 1.5f, 3.f});
    scene.propagation.estimator = estimator;
    scene.propagation.raysPerFrame = 500;
    scene.propagation.irLength = 0.5f;
    scene.propagation.threads = 1;
    scene.propagation.seed = 7;
    Simulation fresh(scene);
    scene.propagation.seed = 3;
    Simulation reused(scene);
    for (int f = 0; f < 3; ++f) reused.runFrame({2.f, 1.5f, 2.f});  // another point and seed
    reused.restart(7);
    for (int f = 0; f < 3; ++f) {
      fresh.runFrame({4.f, 1.5f, 3.f});
      reused.runFrame({4.f, 1.5f, 3.f});
      INFO("estimator " << int(estimator) << ", frame " << f);
      CHECK(test::identical(fresh.result(0).energy, reused.result(0).energy));
      CHECK(fresh.framesRun() == reused.framesRun());
    }
  }
}
