// dpc-demo: render a scene through the diffuse path cache, offline to a WAV file (live
// playback builds on the same pipeline).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "apps/pipeline/offline_renderer.h"
#include "audio/wav_io.h"
#include "engine/input_error.h"
#include "engine/scene.h"

using namespace dpc;

namespace {

struct Flags {
  std::string scene, offline, irOut, estimator, weighting;
  double duration = 0.0, tau = 0.0, gainDb = 0.0;
  int64_t seed = 0, rays = 0, maxOrder = 0, threads = 0;
  bool quiet = false;
  // Which options the user gave (so that any value, even a sentinel-looking one, is checked).
  bool hasDuration = false, hasTau = false, hasGain = false, hasSeed = false, hasRays = false,
       hasMaxOrder = false, hasThreads = false;
};

void progressBar(double done, double total) {
  const int width = 40;
  const double f = total > 0 ? std::min(1.0, done / total) : 1.0;
  const int filled = int(f * width);
  if (isatty(STDERR_FILENO)) {
    std::fprintf(stderr, "\r[%.*s%*s] %3d%%  %.1f / %.1f s", filled,
                 "########################################", width - filled, "", int(f * 100),
                 done, total);
    if (f >= 1.0) std::fprintf(stderr, "\n");
  } else if (int(f * 100) % 10 == 0) {
    std::fprintf(stderr, "progress %3d%%  %.1f / %.1f s\n", int(f * 100), done, total);
  }
}

PropagationSettings applyOverrides(const SceneDesc& scene, const Flags& fl) {
  PropagationSettings s = scene.propagation;
  auto bad = [&](const char* flag, const std::string& why) {
    throw InputError("command line", flag, why);
  };
  if (fl.hasSeed) {
    if (fl.seed < 0) bad("--seed", "must be >= 0");
    s.seed = uint64_t(fl.seed);
  }
  if (fl.hasRays) {
    if (fl.rays <= 0) bad("--rays", "must be > 0");
    s.raysPerFrame = int(fl.rays);
  }
  if (fl.hasMaxOrder) {
    if (fl.maxOrder < 0) bad("--max-order", "must be >= 0");
    s.maxOrder = int(fl.maxOrder);
  }
  if (fl.hasTau) {
    if (!(fl.tau >= 0.0)) bad("--tau", "must be >= 0 seconds");
    s.cacheTau = float(fl.tau);
  }
  if (fl.hasThreads) {
    if (fl.threads < 0) bad("--threads", "must be >= 0");
    s.threads = int(fl.threads);
  }
  if (!fl.estimator.empty()) {
    auto e = parseEstimator(fl.estimator);
    if (!e) bad("--estimator", "'" + fl.estimator + "' is not dpc or path_tracing");
    s.estimator = *e;
  }
  if (!fl.weighting.empty()) {
    auto w = parseDpcWeighting(fl.weighting);
    if (!w) bad("--dpc-weighting", "'" + fl.weighting + "' is not ema or seed");
    s.dpcWeighting = *w;
  }
  return s;
}

int runOffline(const Flags& fl) {
  SceneDesc scene = loadScene(fl.scene);
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  const PropagationSettings settings = applyOverrides(scene, fl);
  if (fl.hasDuration && !(fl.duration > 0.0))
    throw InputError("command line", "--duration", "must be > 0 seconds");
  const DrySignals dry = loadDrySignals(scene);
  for (const std::string& n : dry.notes) std::fprintf(stderr, "note: %s\n", n.c_str());

  OfflineOptions opt;
  opt.durationSeconds = fl.hasDuration ? fl.duration : -1.0;
  if (!fl.quiet) opt.progress = progressBar;
  const OfflineResult r = renderOffline(scene, settings, dry, opt);

  // Level: by default normalise the peak to -1 dBFS; --gain-db sets a fixed gain instead.
  audio::AudioData out = r.output;
  float peak = 0.f;
  for (const auto& ch : out.channels)
    for (float x : ch) peak = std::max(peak, std::abs(x));
  double gainDb = fl.gainDb;
  if (!fl.hasGain) gainDb = peak > 0.f ? -1.0 - 20.0 * std::log10(peak) : 0.0;
  const float gain = float(std::pow(10.0, gainDb / 20.0));
  for (auto& ch : out.channels)
    for (float& x : ch) x *= gain;
  audio::writeWav(fl.offline, out, audio::SampleFormat::kFloat32);
  if (!fl.irOut.empty()) {
    audio::AudioData ir;
    ir.sampleRate = scene.audio.sampleRate;
    for (const auto& source : r.lastIrs)
      for (const auto& channel : source) ir.channels.push_back(channel);
    audio::writeWav(fl.irOut, ir, audio::SampleFormat::kFloat32);
  }

  const double audioSeconds = double(out.frames()) / scene.audio.sampleRate;
  const auto& t = r.totals;
  std::printf("wrote %s (%.2f s, %d Hz, float32, gain %+.1f dB)\n", fl.offline.c_str(),
              audioSeconds, scene.audio.sampleRate, gainDb);
  if (!fl.irOut.empty())
    std::printf("wrote %s (last frame's IR, %zu channel(s): source-major)\n", fl.irOut.c_str(),
                r.lastIrs.size() * r.lastIrs.front().size());
  std::printf(
      "frames %llu  IRs applied %llu  rays/s %.3g  segments/s %.3g  cache entries %zu (%.1f MB)\n"
      "propagation %.2f s (trace %.2f, IR synthesis %.2f, partition+FFT %.2f)  wall %.2f s  "
      "real-time factor %.1fx\n",
      (unsigned long long)t.frames, (unsigned long long)r.irsApplied,
      t.traceSeconds > 0 ? t.rays / t.traceSeconds : 0.0,
      t.traceSeconds > 0 ? t.segments / t.traceSeconds : 0.0, r.cacheEntries,
      r.cacheBytes / 1e6, t.traceSeconds + t.synthesisSeconds + t.prepareSeconds,
      t.traceSeconds, t.synthesisSeconds, t.prepareSeconds, r.wallSeconds,
      audioSeconds / r.wallSeconds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "dpc-demo: interactive sound propagation with the diffuse path cache.\n"
      "Renders SCENE.json offline to a WAV file (--offline), moving the listener along the\n"
      "scene's trajectory. Flags override the scene's propagation settings."};
  Flags fl;
  app.add_option("scene", fl.scene, "Scene file (JSON; see docs/scene-format.md)")->required();
  app.add_option("--offline", fl.offline, "Render offline to this WAV file (float32)");
  app.add_option("--duration", fl.duration,
                 "Seconds to render (default: longest source + IR length)");
  app.add_option("--seed", fl.seed, "Random seed (same seed: bit-identical output)");
  app.add_option("--rays", fl.rays, "Rays per source per frame");
  app.add_option("--max-order", fl.maxOrder, "Maximum reflection order");
  app.add_option("--tau", fl.tau, "Cache response time tau, seconds (0 = path tracing)");
  app.add_option("--estimator", fl.estimator, "dpc | path_tracing");
  app.add_option("--dpc-weighting", fl.weighting,
                 "ema (unbiased, default) | seed (thesis eq. 3.2; biased high)");
  app.add_option("--threads", fl.threads, "Tracing threads (0 = all cores)");
  app.add_option("--ir-out", fl.irOut, "Also write the last frame's IR (all channels) as WAV");
  app.add_option("--gain-db", fl.gainDb,
                 "Fixed output gain in dB (default: normalise the peak to -1 dBFS)");
  app.add_flag("--quiet", fl.quiet, "No progress bar");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  fl.hasDuration = app.count("--duration") > 0;
  fl.hasTau = app.count("--tau") > 0;
  fl.hasGain = app.count("--gain-db") > 0;
  fl.hasSeed = app.count("--seed") > 0;
  fl.hasRays = app.count("--rays") > 0;
  fl.hasMaxOrder = app.count("--max-order") > 0;
  fl.hasThreads = app.count("--threads") > 0;
  try {
    if (fl.offline.empty()) {
      std::fprintf(stderr,
                   "dpc-demo: live playback is not available in this build; render with "
                   "--offline OUT.wav\n");
      return 2;
    }
    return runOffline(fl);
  } catch (const InputError& e) {
    std::fprintf(stderr, "dpc-demo: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dpc-demo: error: %s\n", e.what());
    return 1;
  }
}
