// The live pipeline (control, propagation and audio threads, SPSC queues, seqlock pose,
// recorder ring) under ThreadSanitizer: scripts/tsan.sh builds this without the interposing
// allocator and fails on any reported race.
#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "apps/pipeline/live_session.h"

using namespace dpc;

TEST_CASE("Live pipeline threads under ThreadSanitizer", "[tsan]") {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  scene.audio.blockSize = 128;
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 256;
  ps.maxOrder = 30;
  ps.irLength = 0.5f;
  ps.frameRate = 60.f;  // many swaps in a short test
  const DrySignals dry = loadDrySignals(scene);
  LiveSession::Options opt;
  opt.recordSeconds = 10.0;  // exercise the recorder ring too
  LiveSession session(scene, ps, dry, opt);
  session.setPose(listenerPositionAt(scene.listener, 0.0), 0.f, 0.0);
  session.start();

  const int blocks = 1500;
  std::vector<float> left(128), right(128);
  float* out[2] = {left.data(), right.data()};
  bool finite = true;
  std::thread audio([&] {

    for (int b = 0; b < blocks; ++b) {
      session.render(out, 128);
      for (float x : left) finite = finite && std::isfinite(x);
      // Pace like a device at ~4x real time so that frames (60/s) keep arriving.
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  });
  // Control thread: walk the listener meanwhile.
  const auto start = std::chrono::steady_clock::now();
  while (session.status().blocks < uint64_t(blocks)) {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    session.setPose(listenerPositionAt(scene.listener, t), 0.f, t);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  audio.join();
  session.stop();
  const LiveSession::Status st = session.status();
  INFO("blocks " << st.blocks << ", IRs applied " << st.irsApplied);
  CHECK(st.blocks == uint64_t(blocks));
  CHECK(st.irsApplied >= 30);  // swaps happened while the threads raced

  CHECK(finite);
  CHECK(st.nanBlocks == 0);
  const audio::AudioData rec = session.takeRecording();
  CHECK(rec.frames() == size_t(blocks) * 128);
}
