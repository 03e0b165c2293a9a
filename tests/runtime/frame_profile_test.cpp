// The frame profile (runtime/frame_profile.h) accounts for a live frame as a host sees it: a
// session stepped frame by frame, each step timed by the test's own clock around step(). The
// stages a frame passes through (trace, pairs, synthesis, partition, publish, snapshot) are
// each recorded once per frame, they never add up to more than the frame, and they leave
// only the pose assembly and counters unaccounted for. Each pair part is present exactly when
// the scene asks for it (exact paths with exact_order > 0, none with 0).
#include <catch2/catch.hpp>
#include <chrono>
#include <string>

#include "runtime/live_session.h"
#include "scene/scene.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

struct Stepped {
  FrameProfile::Snapshot profile;
  double stepSeconds = 0.0;  ///< the last step() by the test's clock
};

Stepped stepFrames(const SceneDesc& scene, const PropagationSettings& ps, int frames) {
  const DrySignals dry = loadDrySignals(scene);
  LiveSession session(test::shared(scene), ps, test::shared(dry), LiveSession::Options{});
  Stepped out;
  for (int f = 0; f < frames; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    REQUIRE(session.step());
    out.stepSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  out.profile = session.frameProfile();
  return out;
}

double lastSeconds(const FrameProfile::Snapshot& p, FrameProfile::Stage s) {
  return double(p.stage[size_t(s)].lastNs) * 1e-9;
}

}  // namespace

TEST_CASE("Frame profile: every stage once per frame, together the frame", "[live]") {
  const SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/two_rooms.json");
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 2048;
  ps.exactOrder = 2;
  constexpr int kFrames = 4;
  const Stepped run = stepFrames(scene, ps, kFrames);
  const FrameProfile::Snapshot& p = run.profile;
  double stages = 0.0;
  for (int s = 0; s < FrameProfile::kStages; ++s) {
    INFO(FrameProfile::name(FrameProfile::Stage(s)));
    CHECK(p.stage[size_t(s)].callbacks == uint64_t(kFrames));
    CHECK(p.totalSeconds[size_t(s)] > 0.0);
    if (s != FrameProfile::kFrame) stages += lastSeconds(p, FrameProfile::Stage(s));
  }
  const double frame = lastSeconds(p, FrameProfile::kFrame);
  // The stages are disjoint stretches of the frame (rounded to 1 ns each), and the frame is a
  // stretch of the test's step().
  CHECK(stages <= frame + 1e-8);
  CHECK(frame <= run.stepSeconds);
  // What is left out (the pose assembly, the frame's inputs, the counters) copies a few
  // vectors of a handful of sources: well under a fifth of a frame that traces 2048 rays and
  // synthesises two IRs.
  CHECK(stages >= 0.8 * frame);
  CHECK(p.directCpuSeconds > 0.0);
  CHECK(p.exactCpuSeconds > 0.0);
  CHECK(p.estimatorCpuSeconds > 0.0);
  const auto rows = p.rows();
  CHECK(std::string(rows[FrameProfile::kSynthesis].name) == "synthesis");
  CHECK(rows[FrameProfile::kTrace].frames == uint64_t(kFrames));
  CHECK(rows[FrameProfile::kTrace].maxMs >= rows[FrameProfile::kTrace].medianMs * 0.9375);
}

TEST_CASE("Frame profile: no exact-path time without exact paths", "[live]") {
  const SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 1024;
  ps.exactOrder = 0;
  const Stepped run = stepFrames(scene, ps, 2);
  CHECK(run.profile.exactCpuSeconds == 0.0);
  CHECK(run.profile.estimatorCpuSeconds > 0.0);
}
