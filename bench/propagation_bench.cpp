// `dpc-bench propagation`: the full frame against bare Embree, and IR synthesis times.
#include "bench/propagation_bench.h"

#include <chrono>
#include <cstdio>
#include <vector>

#include "bench/bare_embree.h"
#include "engine/room_volume.h"
#include "engine/simulation.h"
#include "runtime/output_format.h"
#include "runtime/render_pipeline.h"
#include "scene/trajectory.h"
#include "synthesis/mono_synthesizer.h"

namespace dpc::bench {
namespace {

using Clock = std::chrono::steady_clock;

double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

/// What the timed full frames measured.
struct FrameTimes {
  std::vector<double> frameMs, traceMs, estimatorMs, synthMs;
  uint64_t segments = 0, hits = 0;
  double traceSeconds = 0.0;
};

/// Runs one full frame at `listener`, then the source's IR synthesis into `ir`; adds both to t.
void timeFrame(Simulation& sim, IrSynthesizer& synth, const glm::vec3& listener,
               std::vector<float>& ir, FrameTimes& t) {
  const auto t0 = Clock::now();
  sim.runFrame(listener);
  const auto t1 = Clock::now();
  const Simulation::SourceResult& r = sim.result(0);
  synth.synthesize(r.energy, r.direct, ir.data(), sim.specularPaths(0));
  const auto t2 = Clock::now();
  t.frameMs.push_back(msBetween(t0, t1));
  t.synthMs.push_back(msBetween(t1, t2));
  t.traceMs.push_back(r.traceSeconds * 1e3);
  t.estimatorMs.push_back(r.estimatorSeconds * 1e3);
  t.segments += r.trace.segments;
  t.hits += r.trace.listenerHits;
  t.traceSeconds += std::chrono::duration<double>(t1 - t0).count();
}

/// Segments and seconds of the bare Embree loops (bench/bare_embree.h).
struct BareTimes {
  uint64_t segments = 0, packetSegments = 0;
  double seconds = 0.0, packetSeconds = 0.0;
};

/// Two yardsticks for frame f: single rays (rtcIntersect1) and 16-wide packets
/// (rtcIntersect16), the latter being what the full frame uses by default; adds them to b.
void timeBareFrame(const Simulation& sim, const glm::vec3& start, const PropagationSettings& s,
                   int f, BareTimes& b) {
  const BareResult one = traceBare(sim.tracer(), start, s.raysPerFrame, s.maxOrder, s.threads, f);
  b.segments += one.segments;
  b.seconds += one.seconds;
  const BareResult p = traceBare(sim.tracer(), start, s.raysPerFrame, s.maxOrder, s.threads, f,
                                 BareMode::kPacket16);
  b.packetSegments += p.segments;
  b.packetSeconds += p.seconds;
}

/// Spatial IR synthesis of one output format (binaural target: <= 10 ms per source per frame
/// for a 2 s IR at 48 kHz, 4096 rays per frame, one core): a directional frame over the
/// format's directions, then the synthesis of all its channels timed. Returns the times, ms.
std::vector<double> timeSpatialSynthesis(const SceneDesc& scene, const PropagationSettings& s,
                                         const glm::vec3& listener, int frames,
                                         OutputFormat output, int order) {
  SceneDesc spatialScene = scene;
  spatialScene.audio.output = output;
  spatialScene.audio.ambisonicOrder = order;
  PropagationSettings bs = s;
  bs.irLength = 2.0f;
  bs.raysPerFrame = 4096;
  Simulation dsim(spatialScene, bs);
  dsim.enableDirectional(spatialDirections(spatialScene.audio));
  auto spatial = makeSpatialSynthesizer(spatialScene, bs, roomVolume(spatialScene.mesh));
  std::vector<std::vector<float>> buffers(size_t(irChannels(spatialScene.audio)),
                                          std::vector<float>(spatial->lengthSamples()));
  std::vector<float*> channels;
  for (auto& b : buffers) channels.push_back(b.data());
  std::vector<double> ms;
  for (int f = 0; f < std::max(5, frames / 3); ++f) {
    dsim.runFrame(listener);
    const auto t0 = Clock::now();
    spatial->synthesize(dsim.directional(0), dsim.result(0).direct, channels,
                        dsim.specularPaths(0));
    ms.push_back(msBetween(t0, Clock::now()));
  }
  return ms;
}

/// Binaural and AmbiX (orders 1 and 3) IR synthesis per source and frame: adds
/// "binaural_ir_synthesis_ms", "ambix1_ir_synthesis_ms", "ambix3_ir_synthesis_ms" and the
/// settings ("spatial_ir") to j.
void timeSpatialSyntheses(const SceneDesc& scene, const PropagationSettings& s,
                          const glm::vec3& listener, int frames, Json& j) {
  j["binaural_ir_synthesis_ms"] =
      stats(timeSpatialSynthesis(scene, s, listener, frames, OutputFormat::kBinaural, 3));
  for (int order : {1, 3})
    j["ambix" + std::to_string(order) + "_ir_synthesis_ms"] = stats(
        timeSpatialSynthesis(scene, s, listener, frames, OutputFormat::kAmbisonics, order));
  j["spatial_ir"] = {{"seconds", 2.0}, {"rays_per_frame", 4096}, {"threads", 1}};
}

/// The report's settings and its full-frame and bare-Embree figures.
Json report(const CommonOptions& c, const PropagationSettings& s, const Simulation& sim,
            const FrameTimes& t, const BareTimes& b) {
  const double fullRate = double(t.segments) / t.traceSeconds;
  const double bareRate = double(b.segments) / b.seconds;
  const double packetRate = double(b.packetSegments) / b.packetSeconds;
  Json j;
  j["benchmark"] = "propagation";
  j["scene"] = c.scene;
  j["triangles"] = sim.geometry().triangleCount();
  j["threads"] = s.threads;
  j["tracing"] = s.tracing == Tracing::kFromListeners ? "from_listeners" : "from_sources";
  j["rays_per_frame"] = s.raysPerFrame;
  j["max_order"] = s.maxOrder;
  j["roulette"] = s.rouletteThreshold > 0.f;
  j["estimator"] = estimatorName(s.estimator);
  j["tau_s"] = s.cacheTau;
  j["frames"] = c.frames;
  j["full_frame"] = {{"segments_per_second", fullRate},
                     {"segments_per_frame", double(t.segments) / c.frames},
                     {"listener_hits_per_frame", double(t.hits) / c.frames},
                     {"frame_ms", stats(t.frameMs)},
                     {"trace_ms", stats(t.traceMs)},
                     {"estimator_ms", stats(t.estimatorMs)}};
  j["bare_embree"] = {{"segments_per_second", bareRate},
                      {"segments_per_frame", double(b.segments) / c.frames},
                      {"note", "same rays and max order, cosine bounces, no listener/cache"}};
  j["bare_embree_packet16"] = {{"segments_per_second", packetRate},
                               {"segments_per_frame", double(b.packetSegments) / c.frames}};
  j["ratio_full_to_bare"] = fullRate / bareRate;
  j["ratio_full_to_bare_packet16"] = fullRate / packetRate;
  return j;
}

/// The source's cache after the last frame.
Json cacheJson(const Simulation::SourceResult& r0) {
  return {{"entries", r0.cacheEntries},
          {"bytes", r0.cacheBytes},
          {"budget_bytes", r0.cacheBudgetBytes},
          {"coarse_entries", r0.cacheCoarseEntries},
          {"entries_merged", r0.cacheMergedEntries},
          {"merged_energy_fraction", r0.cacheCoarseEnergyFraction}};
}

}  // namespace

int benchPropagation(const CommonOptions& c, const PropagationOptions& o) {
  const Tracing tracing = o.tracing;
  const SceneDesc scene = firstSourceOnly(loadScene(c.scene));
  PropagationSettings s = settingsFor(scene, c);
  if (!c.rays) s.raysPerFrame = 4096;
  if (!c.maxOrder) s.maxOrder = 200;
  if (o.noRoulette) s.rouletteThreshold = 0.f;
  s.tracing = tracing;
  const glm::vec3 listener = listenerPositionAt(scene.listeners[0], 0.0);
  Simulation sim(scene, s);
  sim.recordSurfaces(o.recordSurfaces);
  IrSynthesizer synth(scene.audio.sampleRate, s.irLength, roomVolume(scene.mesh), s.speedOfSound,
                      1);
  // The bare loops' rays leave where the full frame's do: the source, or the listener.
  const glm::vec3 start = tracing == Tracing::kFromListeners ? listener : scene.sources[0].position;
  std::vector<float> ir(synth.lengthSamples());
  FrameTimes warmup, t;
  BareTimes b;
  for (int f = -o.warmupFrames; f < c.frames; ++f) {
    // Full frame and bare loops alternate, so a shared machine's load changes weigh on both.
    timeFrame(sim, synth, listener, ir, f < 0 ? warmup : t);
    if (f >= 0) timeBareFrame(sim, start, s, f, b);
    std::fprintf(stderr, "\rframe %d/%d", f + o.warmupFrames + 1, c.frames + o.warmupFrames);
  }
  std::fprintf(stderr, "\r                      \r");
  Json j = report(c, s, sim, t, b);
  j["warmup_frames"] = o.warmupFrames;
  j["record_surfaces"] = o.recordSurfaces;
  if (!warmup.frameMs.empty()) j["warmup_frame_ms"] = stats(warmup.frameMs);
  j["cache"] = cacheJson(sim.result(0));
  j["ir_synthesis_ms"] = stats(t.synthMs);
  j["ir_samples"] = synth.lengthSamples();
  timeSpatialSyntheses(scene, s, listener, c.frames, j);
  printReport(j);
  return 0;
}

}  // namespace dpc::bench
