// Time to first sound as a host sees it: a live session is started and its audio callback
// called at the block rate, as a device would; the first block holding a sample other than 0
// is what SessionStatus::firstSoundSeconds reports (NaN before it), and the first frame that
// produced it traced the adaptive controller's floor, not the scene's rays, so that it came
// sooner. The oracle is the test's own: it scans the blocks it receives for the first sound.
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "runtime/adaptive_rays.h"
#include "runtime/live_session.h"
#include "scene/scene.h"
#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("Live session: the first block with sound is timed, its frame traced the floor",
          "[live]") {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  const DrySignals dry = loadDrySignals(scene);
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 4096;
  // A 1 s frame period and no latency target: nothing but the first frame lowers the rays.
  ps.frameRate = 1.f;
  LiveSession::Options o;
  o.latencyTargetSeconds = 0.0;
  LiveSession session(test::shared(scene), ps, test::shared(dry), o);
  CHECK(std::isnan(session.status().firstSoundSeconds));
  std::vector<float> left(size_t(session.blockSize())), right(left.size());
  float* out[2] = {left.data(), right.data()};
  const auto start = std::chrono::steady_clock::now();
  session.start();
  bool heard = false;
  double heardAfter = 0.0;  // seconds from start, by the test's clock
  const double block = double(session.blockSize()) / scene.audio.sampleRate;
  while (!heard && std::chrono::steady_clock::now() - start < std::chrono::seconds(30)) {
    const auto before = std::chrono::steady_clock::now();
    session.render(nullptr, out, session.blockSize());
    for (size_t i = 0; i < left.size() && !heard; ++i) heard = left[i] != 0.f || right[i] != 0.f;
    if (heard) heardAfter = std::chrono::duration<double>(before - start).count();
    std::this_thread::sleep_for(std::chrono::duration<double>(block));
  }
  session.stop();
  REQUIRE(heard);
  const LiveSession::Status st = session.status();
  REQUIRE(std::isfinite(st.firstSoundSeconds));
  // The session's start is stamped after the test's clock starts and its block before the
  // test's scan: 0 < reported <= what the test measured.
  CHECK(st.firstSoundSeconds > 0.0);
  CHECK(st.firstSoundSeconds <= heardAfter + 1e-3);
  const AdaptiveRays controller(ps.raysPerFrame, 1.0 / ps.frameRate);
  CHECK(st.raysPerFrameMin == controller.floor());
  CHECK(st.raysPerFrameScene == 4096);
}
