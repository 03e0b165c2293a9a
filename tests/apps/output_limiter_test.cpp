// The session's output limiter: a source 40 dB too hot never drives the device beyond
// the limiter's ceiling, and the session's status reports that it acted.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "audio/limiter.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"
#include "runtime/live_session.h"

using namespace dpc;

TEST_CASE("session output stays within the limiter's ceiling and the status counts it", "[limiter]") {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  scene.audio.blockSize = 128;
  scene.sources[0].gainDb = 40.f;  // speech peaks near 0.5: ~50 at the source
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 256;
  ps.maxOrder = 20;
  ps.irLength = 0.3f;
  const DrySignals dry = loadDrySignals(scene);
  LiveSession session(test::shared(scene), ps, test::shared(dry), LiveSession::Options{});
  session.setPose(listenerPositionAt(scene.listeners[0], 0.0), 0.f, 0.0);
  session.start();
  const float ceiling = audio::Limiter(scene.audio.sampleRate).ceiling();
  std::vector<float> left(128), right(128);
  float* out[2] = {left.data(), right.data()};
  float peak = 0.f;
  // 1.5 s of audio once the first IR has arrived (the speech starts within it).
  const auto t0 = std::chrono::steady_clock::now();
  while (session.status().irsApplied == 0 &&
         std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20)) {
    session.render(nullptr, out, 128);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  for (int b = 0; b < 48000 * 3 / 2 / 128; ++b) {
    session.render(nullptr, out, 128);
    for (size_t i = 0; i < 128; ++i) peak = std::max({peak, std::abs(left[i]), std::abs(right[i])});
  }
  session.stop();
  const LiveSession::Status st = session.status();
  REQUIRE(st.irsApplied > 0);
  CHECK(peak <= ceiling);
  CHECK(peak > 0.5f * ceiling);  // it was loud: the limiter held it at the ceiling
  CHECK(st.overCeilingFrames > 0);
  CHECK(st.limitedFrames >= st.overCeilingFrames);
  CHECK(st.limiterMaxReductionDb > 6.f);
}
