// `dpc-bench listeners`: one propagation pass per listener count, timed frame by frame.
#include "bench/listeners_bench.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <memory>

#include "runtime/render_pipeline.h"
#include "scene/trajectory.h"

namespace dpc::bench {
namespace {

double cpuSeconds() {
  return double(std::clock()) / CLOCKS_PER_SEC;
}

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Listener i of `count`: scene listener i mod n, at a point of its trajectory spread over its
/// span.
void place(const SceneDesc& scene, size_t i, size_t count, double t, WorldState& w) {
  const size_t n = scene.listeners.size();
  const ListenerDesc& d = scene.listeners[i % n];
  const double span = d.trajectory.size() > 1
                          ? d.trajectory.back().timeSeconds - d.trajectory.front().timeSeconds
                          : 0.0;
  const size_t per = (count + n - 1) / n;
  const double ti = t + span * double(i / n) / double(per);
  w.listenerPositions[i] = listenerPositionAt(d, ti);
  w.listenerOrientations[i] = listenerOrientationAt(d, ti);
}

/// Totals of one listener count over the timed frames.
struct CountTimes {
  double traceCpu = 0.0, prepareCpu = 0.0, traceWall = 0.0;
  uint64_t segments = 0, hits = 0;
};

/// One frame at scene time t of the stage for `count` listeners, added to `times`.
void timeFrame(const SceneDesc& scene, PropagationStage& stage, size_t count, double t,
               WorldState& world, CountTimes& times) {
  evaluateWorld(scene, t, world);
  world.listenerPositions.resize(count);
  world.listenerOrientations.resize(count);
  for (size_t i = 0; i < count; ++i) place(scene, i, count, t, world);
  double t0 = cpuSeconds();
  const double w0 = wallSeconds();
  stage.traceWorld(world);
  times.traceWall += wallSeconds() - w0;
  times.traceCpu += cpuSeconds() - t0;
  t0 = cpuSeconds();
  for (size_t l = 0; l < count; ++l) stage.synthesizeIrs(l);
  times.prepareCpu += cpuSeconds() - t0;
  for (size_t src = 0; src < scene.sources.size(); ++src) {
    times.segments += stage.simulation().result(src).trace.segments;
    times.hits += stage.simulation().result(src).trace.listenerHits;
  }
}

/// The report's row for one listener count, and its line on stderr.
Json row(int count, const CountTimes& k, const CountTimes& one, int frames) {
  Json e;
  e["listeners"] = count;
  e["pass_wall_ms_per_frame"] = 1e3 * k.traceWall / frames;
  e["pass_wall_ratio_to_one"] = k.traceWall / one.traceWall;
  e["pass_cpu_ms_per_frame"] = 1e3 * k.traceCpu / frames;
  e["prepare_all_cpu_ms_per_frame"] = 1e3 * k.prepareCpu / frames;
  e["pass_ratio_to_one"] = k.traceCpu / one.traceCpu;
  e["segments_per_frame"] = double(k.segments) / frames;
  e["sphere_hits_per_frame"] = double(k.hits) / frames;
  std::fprintf(stderr,
               "%d listeners: pass wall %.1f ms (x%.2f), CPU %.1f ms (x%.2f), prepare all "
               "%.1f ms, segments %.0f\n",
               count, 1e3 * k.traceWall / frames, k.traceWall / one.traceWall,
               1e3 * k.traceCpu / frames, k.traceCpu / one.traceCpu, 1e3 * k.prepareCpu / frames,
               double(k.segments) / frames);
  return e;
}

Json report(const CommonOptions& c, const ListenersOptions& o, const SceneDesc& scene,
            const PropagationSettings& s, const std::vector<CountTimes>& times) {
  Json j;
  j["warmup_frames"] = o.warmupFrames;
  j["machine"] = "shared 2-core machine under load from other builds: ratios within one run";
  j["scene"] = c.scene;
  j["sources"] = scene.sources.size();
  j["rays_per_frame"] = s.raysPerFrame;
  j["frames"] = c.frames;
  j["estimator"] = estimatorName(s.estimator);
  Json rows = Json::array();
  for (size_t k = 0; k < o.counts.size(); ++k)
    rows.push_back(row(o.counts[k], times[k], times[0], c.frames));
  j["listeners"] = rows;
  j["note"] =
      "pass: one traceWorld (every source's rays traced once against all listener spheres, "
      "then each source-listener pair's cache); prepare all: IR synthesis + partition/FFT for "
      "every listener (offline needs all, live only the played one); wall-clock frame time "
      "(what the frame rate sees) and process CPU time of the frames after warmup_frames (the "
      "first frames fill the caches and fault in their memory)";
  return j;
}

}  // namespace

int benchListeners(const CommonOptions& c, const ListenersOptions& o) {
  const auto shared = std::make_shared<const SceneDesc>(loadScene(c.scene));
  const SceneDesc& scene = *shared;
  const PropagationSettings s = settingsFor(scene, c);
  std::vector<std::unique_ptr<PropagationStage>> stages;
  for (size_t k = 0; k < o.counts.size(); ++k)
    stages.push_back(std::make_unique<PropagationStage>(shared, s));
  std::vector<CountTimes> times(o.counts.size());
  WorldState world;
  for (int f = -o.warmupFrames; f < c.frames; ++f) {
    const double t = double(f + o.warmupFrames) / s.frameRate;
    // Steady state from frame 0 on: caches filled, their memory touched.
    if (f == 0) std::fill(times.begin(), times.end(), CountTimes{});
    for (size_t k = 0; k < o.counts.size(); ++k)
      timeFrame(scene, *stages[k], size_t(o.counts[k]), t, world, times[k]);
    std::fprintf(stderr, "\rframe %d/%d", f + o.warmupFrames + 1, c.frames + o.warmupFrames);
  }
  std::fprintf(stderr, "\n");
  printReport(report(c, o, scene, s, times));
  return 0;
}

}  // namespace dpc::bench
