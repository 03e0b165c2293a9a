// The audio stage plays dry * IR: what AudioStage renders from the sets an IrExchange hands it
// equals, once a swap has finished at every partition level, the direct convolution of the
// whole dry history with the newest published set's IRs (computed here by the definition of
// convolution, in double precision: none of dpc's FFT code). Checked across three swaps, one of
// them a set superseded in the mailbox before the audio stage took it (newest wins), and with
// two sources summed into two channels.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "audio/rt_check.h"
#include "runtime/audio_stage.h"
#include "runtime/propagation_stage.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

constexpr int kFs = 16000;
constexpr int kBlock = 64;
/// Blocks after a publication by which every partition level has taken the set and finished
/// its crossfade: at most two chunks of the longest level (2048 samples = 32 blocks here;
/// checked below from the layout).
constexpr size_t kSettleBlocks = 100;
constexpr size_t kWindowBlocks = 16;

SceneDesc twoSourceRoom() {
  SceneDesc s = test::makeShoebox({7, 3, 5}, Bands(0.2f), 0.5f, {1.5f, 1.4f, 1.2f},
                                  {5, 1.6f, 3.5f});
  SourceDesc second = s.sources.front();
  second.name = "second";
  second.position = {5.5f, 1.2f, 1.0f};
  s.sources.push_back(second);
  s.audio.sampleRate = kFs;
  s.audio.blockSize = kBlock;
  s.audio.output = OutputFormat::kStereo;
  s.propagation.irLength = 0.25f;
  s.propagation.raysPerFrame = 400;
  return s;
}

/// y_c[n] = sum_s sum_m x_s[n - m] h_sc[m] for n in [from, to), by the definition.
std::vector<std::vector<double>> directConvolution(const std::vector<std::vector<float>>& x,
                                                   const std::vector<ImpulseResponse>& h,
                                                   size_t from, size_t to) {
  std::vector<std::vector<double>> y(size_t(h[0].channels()), std::vector<double>(to - from));
  for (size_t s = 0; s < h.size(); ++s)
    for (int c = 0; c < h[s].channels(); ++c) {
      const float* hc = h[s].channel(c);
      for (size_t n = from; n < to; ++n) {
        double acc = 0.0;
        for (size_t m = 0; m < h[s].samples() && m <= n; ++m) acc += double(x[s][n - m]) * hc[m];
        y[size_t(c)][n - from] += acc;
      }
    }
  return y;
}

/// Largest |a - b| over the window, relative to the largest |b|.
double relativeError(const std::vector<std::vector<float>>& played, size_t from,
                     const std::vector<std::vector<double>>& expected) {
  double peak = 0.0, worst = 0.0;
  for (size_t c = 0; c < expected.size(); ++c)
    for (size_t i = 0; i < expected[c].size(); ++i) {
      peak = std::max(peak, std::abs(expected[c][i]));
      worst = std::max(worst, std::abs(double(played[c][from + i]) - expected[c][i]));
    }
  return worst / peak;
}

}  // namespace

TEST_CASE("AudioStage: output equals dry * the newest IR after every swap", "[runtime][audio]") {
  const SceneDesc scene = twoSourceRoom();
  const auto shared = test::shared(scene);
  PropagationStage stage(shared, scene.propagation);
  const audio::NonUniformLayout& layout = *stage.layout();
  const auto& last = layout.level(layout.numLevels() - 1);
  REQUIRE(size_t(2 * last.period) < kSettleBlocks);
  const auto exchange = stage.makeExchange(1, 3);
  auto dry = std::make_shared<DrySignals>();  // host inputs are played, not these
  dry->samples.assign(2, std::vector<float>(1, 0.f));
  dry->loop.assign(2, false);
  AudioStage audio(stage, dry, *exchange);
  audio.setSkipSilentLevels(false);

  // Three listener positions: three different sets of IRs.
  const std::vector<glm::vec3> positions = {{5, 1.6f, 3.5f}, {2.5f, 1.5f, 3.8f}, {4, 1.7f, 1.5f}};
  const size_t blocks = positions.size() * (kSettleBlocks + kWindowBlocks);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.f, 0.3f);
  std::vector<std::vector<float>> x(2, std::vector<float>(blocks * kBlock));
  for (auto& xs : x)
    for (float& v : xs) v = noise(rng);
  std::vector<std::vector<float>> y(2, std::vector<float>(blocks * kBlock));

  WorldState world;
  evaluateWorld(scene, 0.0, world);
  std::vector<std::vector<ImpulseResponse>> published;
  const auto publish = [&](const glm::vec3& at) {
    world.listenerPositions[0] = at;
    stage.traceWorld(world);
    IrSet* set = exchange->acquire();
    REQUIRE(set);
    stage.prepare(0, *set);
    exchange->publish(0, set);
    return stage.lastIrs(0);
  };
  size_t block = 0;
  for (size_t k = 0; k < positions.size(); ++k) {
    if (k == 1) publish(positions[0] + glm::vec3(0.3f, 0.f, 0.f));  // superseded: never heard
    published.push_back(publish(positions[k]));
    const audio::rt::ScopedThreadRole role(audio::rt::ThreadRole::kAudio);
    for (size_t b = 0; b < kSettleBlocks + kWindowBlocks; ++b, ++block) {
      const float* in[2] = {x[0].data() + block * kBlock, x[1].data() + block * kBlock};
      float* out[2] = {y[0].data() + block * kBlock, y[1].data() + block * kBlock};
      audio.process(out, in);
    }
  }
  CHECK(audio.irsApplied() == positions.size());
  CHECK(exchange->superseded() == 1);

  for (size_t k = 0; k < positions.size(); ++k) {
    const size_t from = (k * (kSettleBlocks + kWindowBlocks) + kSettleBlocks) * kBlock;
    const size_t to = from + kWindowBlocks * kBlock;
    // Float FFT convolution of a 4000-tap IR: rounding near 1e-6 of the signal; a wrong or a
    // half-swapped IR is off by the order of the signal itself.
    const double error = relativeError(y, from, directConvolution(x, published[k], from, to));
    INFO("set " << k << ": largest error " << 20 * std::log10(error) << " dB of the peak");
    CHECK(error < 1e-4);
    if (k > 0) {  // the previous set's prediction does not fit: the swap happened
      const double stale = relativeError(y, from, directConvolution(x, published[k - 1], from, to));
      CHECK(stale > 1e-2);
    }
  }
}
