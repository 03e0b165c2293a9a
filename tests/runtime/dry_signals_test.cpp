// The dry signals' memory estimate (drySignalBytes, from the files' headers) against what
// loadDrySignals holds, and the workload check naming the signals when they are what does not
// fit.
#include "runtime/dry_signals.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "audio/wav_io.h"
#include "common/input_error.h"
#include "engine/workload.h"
#include "runtime/offline_renderer.h"
#include "testing/temp_dir.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

void writeTone(const std::string& path, int rate, int channels, size_t frames) {
  audio::AudioData a;
  a.sampleRate = rate;
  a.channels.assign(size_t(channels), std::vector<float>(frames));
  for (auto& ch : a.channels)
    for (size_t i = 0; i < frames; ++i) ch[i] = 0.1f * float(std::sin(0.01 * double(i)));
  audio::writeWav(path, a);
}

}  // namespace

TEST_CASE("the dry signals' memory is estimated from the headers as loading holds it",
          "[dry_signals]") {
  const test::TempDir dir("dpc_dry_signals");
  const std::string stereo = (dir.path() / "stereo22k.wav").string();
  const std::string mono = (dir.path() / "mono48k.wav").string();
  writeTone(stereo, 22050, 2, 22050);  // 1 s, resampled to 48 kHz: 48000 floats held
  writeTone(mono, 48000, 1, 10000);
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.2f), 0.5f, {2, 1.5f, 2}, {7, 1.6f, 5});
  scene.audio.sampleRate = 48000;
  scene.sources.resize(3, scene.sources.front());
  scene.sources[0].signalPath = stereo;
  scene.sources[1].signalPath = mono;
  scene.sources[2].signalPath = "";  // host input only: nothing held
  const double estimate = drySignalBytes(scene);
  const DrySignals dry = loadDrySignals(scene);
  double held = 0.0;
  for (const auto& x : dry.samples) held += double(x.size() * sizeof(float));
  // The estimate: what is held (the resampler's length may differ by a sample per source)
  // plus the largest file read whole, the stereo one: 22050 x 2 channels x 4 bytes.
  const double largestRead = 22050.0 * 2 * sizeof(float);
  CHECK(std::abs(estimate - largestRead - held) <= 2 * sizeof(float));
  CHECK(held == Approx((48000.0 + 10000.0) * sizeof(float)).margin(8));
  // An unreadable file counts 0 here; loading names it.
  scene.sources[1].signalPath = (dir.path() / "missing.wav").string();
  CHECK(drySignalBytes(scene) == Approx(48000.0 * sizeof(float) + largestRead).margin(8));
}

TEST_CASE("dry signals beyond the memory available are refused, naming the signals",
          "[dry_signals]") {
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.2f), 0.5f, {2, 1.5f, 2}, {7, 1.6f, 5});
  scene.path = "room.json";
  PropagationSettings ps;
  WorkloadEstimate e = estimateWorkload(scene, ps, 2, 10.0);
  const double limit = 2.0 * (e.irBytes + e.cacheBytes);
  CHECK_NOTHROW(checkWorkload(scene, ps, e, limit));
  e.signalBytes = 2.0 * limit;  // signals alone are twice what is available
  CHECK_THROWS_WITH(
      checkWorkload(scene, ps, e, limit),
      Catch::StartsWith("room.json: sources[].signal: ") && Catch::Contains("dry signals"));
}

TEST_CASE("sources playing one file share its conversion, each with its own gain",
          "[dry_signals]") {
  const test::TempDir dir("dpc_dry_signals_shared");
  const std::string file = (dir.path() / "voice22k.wav").string();
  writeTone(file, 22050, 1, 11025);  // 0.5 s, resampled to 48 kHz
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.2f), 0.5f, {2, 1.5f, 2}, {7, 1.6f, 5});
  scene.audio.sampleRate = 48000;
  scene.sources.resize(3, scene.sources.front());
  for (SourceDesc& s : scene.sources) s.signalPath = file;
  scene.sources[1].gainDb = -6.0f;
  scene.sources[2].gainDb = 12.0f;
  const DrySignals dry = loadDrySignals(scene);
  REQUIRE(dry.samples.size() == 3);
  REQUIRE(dry.samples[0].size() == dry.samples[1].size());
  REQUIRE(dry.samples[0].size() == dry.samples[2].size());
  CHECK(dry.samples[0].size() == Approx(24000).margin(2));
  // The same conversion scaled by each source's gain: equal up to the float product's rounding.
  const float g1 = float(std::pow(10.0, -6.0 / 20.0)), g2 = float(std::pow(10.0, 12.0 / 20.0));
  double worst = 0.0;
  for (size_t n = 0; n < dry.samples[0].size(); ++n) {
    worst = std::max(worst, double(std::abs(dry.samples[1][n] - g1 * dry.samples[0][n])));
    worst = std::max(worst, double(std::abs(dry.samples[2][n] - g2 * dry.samples[0][n])));
  }
  CHECK(worst <= 1e-6);
  // One resampling note for the file, not one per source.
  CHECK(std::count_if(dry.notes.begin(), dry.notes.end(), [](const std::string& n) {
          return n.find("resampled") != std::string::npos;
        }) == 1);
}

TEST_CASE("a looping dry signal plays as the same signal written out over the whole render",
          "[dry_signals]") {
  // Loops shorter than a block (wrapping several times within one), longer than it but not a
  // multiple of it (wrapping inside some blocks, read in place in others). The convolution is
  // linear and the same IRs are traced (same seed), so the outputs are bit-identical.
  SceneDesc scene = test::makeShoebox({6, 3, 4}, Bands(0.3f), 0.3f, {1.5f, 1.5f, 1.5f},
                                      {4.2f, 1.6f, 2.4f});
  scene.audio.sampleRate = 48000;
  scene.audio.blockSize = 256;
  scene.propagation.raysPerFrame = 256;
  OfflineOptions opt;
  opt.durationSeconds = 0.25;
  const size_t total = 12000 + 48000;  // the render and the IR's ring-out, at most
  for (size_t period : {size_t(100), size_t(1001)}) {
    std::vector<float> loop(period);
    for (size_t n = 0; n < period; ++n) loop[n] = float(std::sin(0.37 * double(n))) + 0.01f * n;
    DrySignals looping;
    looping.samples = {loop};
    looping.loop = {1};
    DrySignals written;
    written.samples = {std::vector<float>(total)};
    for (size_t n = 0; n < total; ++n) written.samples[0][n] = loop[n % period];
    written.loop = {0};
    const OfflineResult a =
        renderOffline(test::shared(scene), scene.propagation, test::shared(looping), opt);
    const OfflineResult b =
        renderOffline(test::shared(scene), scene.propagation, test::shared(written), opt);
    REQUIRE(a.listeners.size() == 1);
    INFO("loop of " << period << " samples");
    CHECK(a.listeners[0].output.channels == b.listeners[0].output.channels);
    CHECK(a.listeners[0].output.frames() == 12000);
  }
}
