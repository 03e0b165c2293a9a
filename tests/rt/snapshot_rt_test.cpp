// Real-time rule of the propagation thread's copy for readers (runtime/response_snapshot.h):
// once its buffers have grown, ResponseSnapshot::tryStore makes no heap call, also for a pair
// played from a bake, whose response it interpolates again into a scratch it reuses.
#include <catch2/catch.hpp>
#include <memory>

#include "alloc_counter.h"
#include "runtime/propagation_stage.h"
#include "runtime/response_snapshot.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("ResponseSnapshot::tryStore of a baked pair makes no heap call once grown", "[rt]") {
  auto scene = std::make_shared<SceneDesc>(
      test::makeShoebox({10.f, 3.f, 7.f}, Bands(0.2f), 0.5f, {2.f, 1.6f, 3.5f}, {8.f, 1.6f, 3.5f}));
  scene->propagation.raysPerFrame = 500;
  scene->propagation.irLength = 0.5f;
  scene->propagation.exactOrder = 0;  // no exact paths: their count may change between frames
  PropagationStage stage(scene, scene->propagation);
  WorldState world;
  evaluateWorld(*scene, 0.0, world);
  // A bake with one probe at the listener (weight 1 there) and the scene's source.
  auto field = std::make_shared<BakedField>();
  field->probes = {world.listenerPositions[0]};
  field->sources = {scene->sources[0].position};
  field->bins = 500;
  field->late.assign(field->bins * kNumBands, 1e-3f);
  fillUniformDirections(*field);
  stage.attachBake(field);
  ResponseSnapshot snapshot;
  uint64_t heapCalls = ~0ull;
  for (int f = 0; f < 3; ++f) {
    stage.traceWorld(world);
    stage.synthesizeIrs(0);
    rt::markAudioThread(f == 2);  // count the third copy's heap calls only
    const rt::AllocationCounts before = rt::audioThreadAllocations();
    REQUIRE(snapshot.tryStore(stage, world, 0, uint64_t(f)));
    heapCalls = (rt::audioThreadAllocations() - before).total();
    rt::markAudioThread(false);
  }
  bool fromBake = false;
  REQUIRE(snapshot.read(0, [&](const ResponseSnapshot::Responses& r) { fromBake = r.fromBake; }));
  CHECK(fromBake);
  CHECK(heapCalls == 0);
}
