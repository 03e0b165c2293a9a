// Any host callback size: LiveSession::render called with random frame counts 1..4096 gives
// the same samples as calls of exactly one engine block, both delayed by the adapter's stated
// latency, and makes no heap calls on the calling (audio) thread.
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "alloc_counter.h"
#include "runtime/live_session.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

constexpr int kBlock = 128;
constexpr int kTotal = 3 * 48000;  // frames rendered per session

/// A session holding exactly one propagation frame's IRs (the first, traced with one thread
/// from a fixed pose, so two sessions get the same IRs): started, then stopped as soon as that
/// frame is queued; the next frame would come 5 s later (frame rate 0.2 Hz).
std::unique_ptr<LiveSession> oneFrameSession(const SceneDesc& scene, const DrySignals& dry) {
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 512;
  ps.maxOrder = 20;
  ps.irLength = 0.5f;
  ps.frameRate = 0.2f;
  ps.threads = 1;
  LiveSession::Options opt;
  auto session = std::make_unique<LiveSession>(test::shared(scene), ps, test::shared(dry), opt);
  session->setPose(scene.listeners[0].position, 0.f, 0.0);
  session->start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (session->status().frames < 1 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  session->stop();
  return session;
}

struct Rendered {
  std::vector<float> left, right;
  uint64_t heapCalls = 0;
};

/// Renders kTotal frames in calls of the given sizes (cycled), from `inputs` (one channel per
/// source, kTotal frames each) or the scene's own signals (inputs empty).
Rendered renderInCalls(LiveSession& session, const std::vector<int>& sizes,
                       const std::vector<std::vector<float>>& inputs) {
  Rendered r;
  r.left.assign(kTotal, 0.f);
  r.right.assign(kTotal, 0.f);
  std::vector<const float*> in(inputs.size());
  rt::AllocationScope scope;
  size_t i = 0;
  for (int done = 0; done < kTotal;) {
    const int n = std::min(sizes[i++ % sizes.size()], kTotal - done);
    float* out[2] = {r.left.data() + done, r.right.data() + done};
    for (size_t s = 0; s < inputs.size(); ++s) in[s] = inputs[s].data() + done;
    session.render(inputs.empty() ? nullptr : in.data(), out, n);
    done += n;
  }
  r.heapCalls = scope.counts().total();
  return r;
}

}  // namespace

TEST_CASE("LiveSession::render: random callback sizes 1..4096 equal fixed blocks", "[rt]") {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  scene.audio.blockSize = kBlock;
  const DrySignals dry = loadDrySignals(scene);

  std::mt19937 rng(7);
  std::uniform_int_distribution<int> size(1, 4096);
  std::vector<int> randomSizes(4000);
  for (int& n : randomSizes) n = size(rng);

  for (const bool hostInputs : {false, true}) {
    DYNAMIC_SECTION((hostInputs ? "host inputs" : "scene signals")) {
      std::vector<std::vector<float>> inputs;
      if (hostInputs) {
        std::normal_distribution<float> noise(0.f, 0.1f);
        inputs.assign(scene.sources.size(), std::vector<float>(kTotal));
        for (auto& ch : inputs)
          for (float& x : ch) x = noise(rng);
      }
      auto fixedSession = oneFrameSession(scene, dry);
      auto randomSession = oneFrameSession(scene, dry);
      REQUIRE(fixedSession->status().frames == 1);
      REQUIRE(randomSession->status().frames == 1);
      REQUIRE(fixedSession->adapterLatencyFrames() == kBlock);
      REQUIRE(randomSession->sourceCount() == int(scene.sources.size()));

      const Rendered fixed = renderInCalls(*fixedSession, {kBlock}, inputs);
      const Rendered random = renderInCalls(*randomSession, randomSizes, inputs);
      CHECK(fixed.heapCalls == 0);
      CHECK(random.heapCalls == 0);

      // The adapter's latency: the first block is silence in both.
      for (int t = 0; t < kBlock; ++t) {
        CHECK(fixed.left[size_t(t)] == 0.f);
        CHECK(random.left[size_t(t)] == 0.f);
      }
      // Same engine blocks from the same IRs and inputs: the same arithmetic, so the samples
      // are equal exactly (no rounding difference can arise from how the host slices time).
      double energy = 0.0;
      size_t mismatches = 0;
      for (size_t t = 0; t < size_t(kTotal); ++t) {
        energy += double(fixed.left[t]) * fixed.left[t];
        if (fixed.left[t] != random.left[t] || fixed.right[t] != random.right[t]) ++mismatches;
      }
      INFO("mismatching samples " << mismatches << " of " << kTotal);
      CHECK(mismatches == 0);
      CHECK(energy > 0.0);  // the IRs were applied: not a comparison of two silences
      const LiveSession::Status st = randomSession->status();
      CHECK(st.rejectedCallbacks == 0);
      CHECK(st.blocks == uint64_t(kTotal / kBlock));
    }
  }
}

TEST_CASE("LiveSession::render: out-of-range callback sizes are counted, not rendered", "[rt]") {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  scene.audio.blockSize = kBlock;
  const DrySignals dry = loadDrySignals(scene);
  LiveSession session(test::shared(scene), scene.propagation, test::shared(dry), {});
  std::vector<float> l(16, 1.f), r(16, 1.f);
  float* out[2] = {l.data(), r.data()};
  session.render(out, 0);
  session.render(out, LiveSession::kMaxCallbackFrames + 1);
  CHECK(session.status().rejectedCallbacks == 2);
  CHECK(session.status().blocks == 0);
}

TEST_CASE("LiveSession: an IR swap spread outside [0, kMaxIrSwapSpreadSeconds] is refused",
          "[rt]") {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  scene.audio.blockSize = kBlock;
  const DrySignals dry = loadDrySignals(scene);
  const auto make = [&](double seconds) {
    LiveSession::Options opt;
    opt.irSwapSpreadSeconds = seconds;
    LiveSession session(test::shared(scene), scene.propagation, test::shared(dry), opt);
  };
  for (double bad : {-1e-3, LiveSession::kMaxIrSwapSpreadSeconds * 1.001, std::nan("")})
    CHECK_THROWS_AS(make(bad), std::invalid_argument);
  CHECK_NOTHROW(make(0.0));
  CHECK_NOTHROW(make(LiveSession::kMaxIrSwapSpreadSeconds));
}
