// What a live session's readers get of each frame (ResponseSnapshot through
// LiveSession::copyResponses), with and without its whole IRs kept.
#include <catch2/catch.hpp>
#include <memory>
#include <string>
#include <vector>

#include "runtime/live_session.h"
#include "scene/scene.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

std::unique_ptr<LiveSession> shoeboxSession(bool keepIrs) {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 1024;
  LiveSession::Options o;
  o.keepImpulseResponses = keepIrs;
  o.adaptiveRays = false;
  return std::make_unique<LiveSession>(test::shared(scene), ps,
                                       test::shared(loadDrySignals(scene)), o);
}

struct Read {
  int irChannels = -1;
  size_t irSamples = 0;
  std::vector<Bands> energy;
  uint64_t frame = 0;
};

Read read(LiveSession& session) {
  Read out;
  REQUIRE(session.copyResponses(0, [&](const LiveSession::Responses& r) {
    out.irChannels = r.ir->channels();
    out.irSamples = r.ir->samples();
    out.energy = *r.energy;
    out.frame = r.frame;
  }));
  return out;
}

}  // namespace

// Oracle: the same frames (same seed and inputs) in a session that keeps its IRs; the energy
// responses are bit-identical, and only the IR is left out.
TEST_CASE("A session that keeps no IRs still reports each frame's responses", "[live]") {
  const auto kept = shoeboxSession(true), lean = shoeboxSession(false);
  for (int f = 0; f < 3; ++f) {
    REQUIRE(kept->step());
    REQUIRE(lean->step());
  }
  const Read a = read(*kept), b = read(*lean);
  CHECK(a.irChannels == kept->irChannels());
  CHECK(a.irSamples > 0);
  CHECK(b.irChannels == 0);
  CHECK(b.frame == a.frame);
  REQUIRE(!a.energy.empty());
  CHECK(b.energy == a.energy);
  double total = 0.0;
  for (const Bands& e : b.energy) total += double(e.sum());
  CHECK(total > 0.0);
}
