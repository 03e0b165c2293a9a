// Pairs played from a bake are not traced (FrameInputs::skippedPairs): from the sources a
// skipped source traces no ray, from the listeners its sphere leaves the pass; the other
// pairs' responses do not change by a bit; the skipped pairs keep their direct sound and
// exact early paths live; and a pair traced again starts its path cache over.
#include <catch2/catch.hpp>
#include <cmath>
#include <glm/geometric.hpp>
#include <vector>

#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

/// A 10 x 3 x 7 m shoebox with three sources and one listener; exact paths off unless asked.
SceneDesc threeSources(Tracing tracing, int exactOrder = 0) {
  SceneDesc s = test::makeShoebox({10, 3, 7}, Bands(0.2f), 0.5f, {2, 1.6f, 3.5f},
                                  {8, 1.6f, 3.5f});
  for (const glm::vec3 p : {glm::vec3(3, 1.2f, 1.5f), glm::vec3(5, 2.f, 5.5f)}) {
    SourceDesc d = s.sources[0];
    d.position = p;
    s.sources.push_back(d);
  }
  s.propagation.raysPerFrame = 1024;
  s.propagation.threads = 1;
  s.propagation.tracing = tracing;
  s.propagation.exactOrder = exactOrder;
  return s;
}

std::vector<glm::vec3> positions(const SceneDesc& s) {
  std::vector<glm::vec3> p;
  for (const SourceDesc& d : s.sources) p.push_back(d.position);
  return p;
}

bool sameBins(const EnergyResponse& a, const EnergyResponse& b) {
  for (size_t k = 0; k < a.binCount(); ++k)
    if (!(a.bins()[k].v == b.bins()[k].v)) return false;
  return true;
}

/// Runs `frames` frames of two simulations of `scene`, the second skipping source 1; checks
/// the unskipped sources bit for bit and source 1's empty response and live direct sound.
void checkSkip(const SceneDesc& scene, int frames) {
  Simulation all(scene), some(scene);
  const ListenerSphere listener{{8, 1.6f, 3.5f}, 0.5f};
  FrameInputs in = Simulation::inputsAt(std::span(&listener, 1), positions(scene));
  for (int f = 0; f < frames; ++f) {
    all.runFrame(in);
    in.skippedPairs = {0, 1, 0};
    some.runFrame(in);
    in.skippedPairs.clear();
    for (const size_t s : {size_t(0), size_t(2)})
      CHECK(sameBins(all.result(s).energy, some.result(s).energy));
    CHECK(some.result(1).energy.total().sum() == 0.f);
    CHECK(all.result(1).energy.total().sum() > 0.f);
    CHECK(some.result(1).direct.intensity.v == all.result(1).direct.intensity.v);
    CHECK(some.result(1).direct.delaySeconds == all.result(1).direct.delaySeconds);
  }
}

/// With every pair skipped and exact paths off (no proposal pass either), a frame traces
/// nothing.
void checkNothingTraced(const SceneDesc& scene) {
  Simulation sim(scene);
  FrameInputs in = sim.inputsAt({8, 1.6f, 3.5f});
  in.skippedPairs = {1, 1, 1};
  sim.runFrame(in);
  CHECK(sim.frameTrace().rays == 0u);
  CHECK(sim.frameTrace().segments == 0u);
}

}  // namespace

TEST_CASE("Skipped pairs from the sources: no ray for the skipped source, others unchanged",
          "[engine][bake]") {
  const SceneDesc scene = threeSources(Tracing::kFromSources);
  checkSkip(scene, 3);
  checkNothingTraced(scene);
  Simulation sim(scene);
  FrameInputs in = sim.inputsAt({8, 1.6f, 3.5f});
  in.skippedPairs = {0, 1, 0};
  sim.runFrame(in);
  CHECK(sim.frameTrace().rays == 2u * 1024u);  // two passes of three
}

TEST_CASE("Skipped pairs from the listeners: the sphere leaves the pass, others' keys unchanged",
          "[engine][bake]") {
  // The DPC keeps paths by identifier across frames, so a bit-identical response over several
  // frames shows that the remaining spheres keep their keys (TraceRequest::receiverIds).
  const SceneDesc scene = threeSources(Tracing::kFromListeners);
  checkSkip(scene, 4);
  checkNothingTraced(scene);
}

namespace {

/// The smallest |delay - |listener - image| / c| over the box's image sources of `order`
/// (Allen & Berkley 1979: along an axis of length a, image n lies at n a + x for even n and
/// (n + 1) a - x for odd n, with |n| reflections off that axis's walls).
double imageDelayError(const SpecularPath& p, glm::vec3 box, glm::vec3 source, glm::vec3 listener,
                       double c) {
  auto coordinate = [](int n, float a, float x) {
    return n % 2 == 0 ? float(n) * a + x : float(n + 1) * a - x;
  };
  const int k = int(p.order);
  double best = 1e9;
  for (int i = -k; i <= k; ++i)
    for (int j = -(k - std::abs(i)); j <= k - std::abs(i); ++j)
      for (const int m : {k - std::abs(i) - std::abs(j), -(k - std::abs(i) - std::abs(j))}) {
        const glm::vec3 image{coordinate(i, box.x, source.x), coordinate(j, box.y, source.y),
                              coordinate(m, box.z, source.z)};
        best = std::min(best, std::abs(p.delaySeconds - double(glm::length(listener - image)) / c));
      }
  return best;
}

}  // namespace

// Oracle: every exact path a skipped source keeps is one of the box's image sources (Allen &
// Berkley), at its delay to 1e-6 s (float positions: about 0.3 mm); the paths both find are
// the same to the bit; and the listener's proposal rays (a whole mirror run of exact_order
// each, one pass for every skipped source) find at least the paths the source's own rays find.
TEST_CASE("Skipped pairs keep their exact early paths live (candidates from the listener)",
          "[engine][bake]") {
  for (const Tracing tracing : {Tracing::kFromSources, Tracing::kFromListeners}) {
    const SceneDesc scene = threeSources(tracing, 3);
    Simulation traced(scene), skipped(scene);
    const glm::vec3 listener{8, 1.6f, 3.5f};
    FrameInputs allSkipped = skipped.inputsAt(listener);
    allSkipped.skippedPairs = {1, 1, 1};
    for (int f = 0; f < 3; ++f) {
      traced.runFrame(listener);
      skipped.runFrame(allSkipped);
    }
    // A proposal ray costs at most exact_order segments.
    CHECK(skipped.frameTrace().segments <= 3u * skipped.frameTrace().rays);
    CHECK(skipped.frameTrace().rays == 1024u);  // one pass for the listener, not three
    for (size_t s = 0; s < 3; ++s) {
      const auto& mine = skipped.specularPaths(s);
      CHECK(mine.size() >= traced.specularPaths(s).size());
      for (const SpecularPath& q : mine)
        CHECK(imageDelayError(q, {10, 3, 7}, scene.sources[s].position, listener, 343.0) < 1e-6);
      for (const SpecularPath& p : traced.specularPaths(s))
        for (const SpecularPath& q : mine)
          if (q.key == p.key) {
            CHECK(q.delaySeconds == p.delaySeconds);
            CHECK(q.intensity.v == p.intensity.v);
          }
    }
  }
}

// Behaviour: a pair traced again after skipped frames reads out exactly what a teleported
// (restarted) pair reads: nothing of the frames before it was skipped survives. Without the
// restart its window would still hold frames 0..2.
TEST_CASE("A pair traced again after skipped frames starts its path cache over",
          "[engine][bake]") {
  for (const Tracing tracing : {Tracing::kFromSources, Tracing::kFromListeners}) {
    const SceneDesc scene = threeSources(tracing);
    Simulation resumed(scene), restarted(scene);
    const ListenerSphere listener{{8, 1.6f, 3.5f}, 0.5f};
    for (int f = 0; f < 8; ++f) {
      FrameInputs in = Simulation::inputsAt(std::span(&listener, 1), positions(scene));
      if (f >= 3 && f < 7) in.skippedPairs = {0, 1, 0};
      resumed.runFrame(in);
      in.skippedPairs.clear();
      if (f == 7) in.sourceRestarts = {0, 1, 0};
      restarted.runFrame(in);
    }
    CHECK(sameBins(resumed.result(1).energy, restarted.result(1).energy));
    CHECK(resumed.result(1).energy.total().sum() > 0.f);
    CHECK(resumed.result(1).cacheEntries == restarted.result(1).cacheEntries);
  }
}
