// ResponseSnapshot (runtime/response_snapshot.h): a store copies the listener's responses, a
// reader holding the lock makes the writer skip rather than wait.
#include "runtime/response_snapshot.h"

#include <catch2/catch.hpp>
#include <thread>

#include "runtime/propagation_stage.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("ResponseSnapshot: copies the traced listener's responses and skips while locked",
          "[snapshot]") {
  SceneDesc s = test::makeShoebox({6, 3, 4}, Bands(0.3f), 0.5f, {1, 1.5f, 1}, {4, 1.5f, 3});
  s.propagation.raysPerFrame = 256;
  s.propagation.irLength = 0.2f;
  PropagationStage stage(test::shared(s), s.propagation);
  WorldState w;
  evaluateWorld(s, 0.0, w);
  stage.traceWorld(w);
  stage.synthesizeIrs(0);

  ResponseSnapshot snap;
  CHECK_FALSE(snap.read(0, [](const ResponseSnapshot::Responses&) {}));  // nothing stored yet
  REQUIRE(snap.tryStore(stage, w, 0, 7));
  bool called = false;
  CHECK(snap.read(0, [&](const ResponseSnapshot::Responses& r) {
    called = true;
    CHECK(*r.ir == stage.lastIrs(0)[0]);
    CHECK(r.frame == 7);
    CHECK(r.binSeconds == Simulation::kEnergyBinSeconds);
    CHECK(r.world->sourcePositions == w.sourcePositions);  // the frame's world, copied
    // The direct sound is added into its bin: the total exceeds the estimator's alone.
    Bands total(0.f);
    for (const Bands& b : *r.energy) total += b;
    CHECK(total[3] > stage.simulation().result(0).energy.total()[3]);
    // While the reader holds the lock, a store on another thread gives up at once.
    bool stored = true;
    std::thread writer([&] { stored = snap.tryStore(stage, w, 0, 8); });
    writer.join();
    CHECK_FALSE(stored);
  }));
  CHECK(called);
  CHECK_FALSE(snap.read(1, [](const ResponseSnapshot::Responses&) {}));  // one source only
}
