// dpc-bench: speed and noise benchmarks. Prints one JSON document on stdout; progress on stderr.
//
//   dpc-bench propagation SCENE [--threads T] [--rays N] [--max-order D] [--frames F]
//                               [--no-roulette] [--tau S]
//   dpc-bench noise SCENE [--rays N] [--frames F] [--tau S] [--walk-speed V]
//                         [--reference-frames M] [--threads T] [--max-order D]
//   dpc-bench dynamic [--rays N] [--frames F] [--parts step,objects,moving_source]
//                     (built-in scenes; no file)
//   dpc-bench listeners SCENE [--rays N] [--frames F] [--threads T] [--counts 1,2,4,8]
//   dpc-bench diffraction SCENE [--frames F]
//   dpc-bench live SCENE [--rays N] [--duration S] [--block-size B] [--frame-rate F]
//                        [--threads T] [--device SPEC]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <glm/geometric.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

#include "audio/audio_device.h"
#include "bench/bare_embree.h"
#include "bench/bench_util.h"
#include "bench/convolve_bench.h"
#include "engine/diffraction.h"
#include "common/input_error.h"
#include "synthesis/ir_synthesis.h"
#include "bench/noise_study.h"
#include "scene/scene.h"
#include "engine/simulation.h"
#include "runtime/live_session.h"
#include "runtime/null_output.h"
#include "runtime/render_pipeline.h"
#include "testing/test_scenes.h"

using namespace dpc;
using json = nlohmann::ordered_json;

namespace {

using bench::percentile;

json stats(const std::vector<double>& v, double scale = 1.0) {
  std::vector<double> s(v);
  for (double& x : s) x *= scale;
  return {{"median", percentile(s, 0.5)},
          {"p95", percentile(s, 0.95)},
          {"min", s.empty() ? NAN : *std::min_element(s.begin(), s.end())},
          {"max", s.empty() ? NAN : *std::max_element(s.begin(), s.end())}};
}

/// The scene with only its first source (benchmarks time one source's frame).
SceneDesc firstSourceOnly(SceneDesc scene) {
  scene.sources.resize(1);
  return scene;
}

struct Common {
  std::string scene;
  int threads = 0, rays = 4096, maxOrder = 200, frames = 30;
  double tau = 1.0, cacheMb = 64.0;
  bool haveCacheMb = false;
  bool haveTau = false, haveMaxOrder = false, haveRays = false;
};

PropagationSettings settingsFor(const SceneDesc& scene, const Common& c) {
  PropagationSettings s = scene.propagation;
  s.threads = c.threads;
  if (c.haveRays) s.raysPerFrame = c.rays;
  if (c.haveMaxOrder) s.maxOrder = c.maxOrder;
  if (c.haveTau) s.cacheTau = float(c.tau);
  if (c.haveCacheMb) s.cacheMemoryMb = float(c.cacheMb);
  return s;
}

int benchPropagation(const Common& c, bool noRoulette) {
  const SceneDesc scene = firstSourceOnly(loadScene(c.scene));
  PropagationSettings s = settingsFor(scene, c);
  if (!c.haveRays) s.raysPerFrame = 4096;
  if (!c.haveMaxOrder) s.maxOrder = 200;
  if (noRoulette) s.rouletteThreshold = 0.f;
  const glm::vec3 listener = listenerPositionAt(scene.listeners[0], 0.0);
  Simulation sim(scene, s);
  IrSynthesizer synth(scene.audio.sampleRate, s.irLength, roomVolume(scene.mesh), s.speedOfSound,
                      1);
  std::vector<float> ir(synth.lengthSamples());
  std::vector<double> frameMs, traceMs, estimatorMs, synthMs;
  uint64_t segments = 0, hits = 0;
  double traceSeconds = 0.0;
  for (int f = 0; f < c.frames; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    sim.runFrame(listener);
    const auto t1 = std::chrono::steady_clock::now();
    const Simulation::SourceResult& r = sim.result(0);
    synth.synthesize(r.energy, r.direct, ir.data());
    const auto t2 = std::chrono::steady_clock::now();
    frameMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    synthMs.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    traceMs.push_back(r.traceSeconds * 1e3);
    estimatorMs.push_back(r.estimatorSeconds * 1e3);
    segments += r.trace.segments;
    hits += r.trace.listenerHits;
    traceSeconds += std::chrono::duration<double>(t1 - t0).count();
    std::fprintf(stderr, "\rframe %d/%d", f + 1, c.frames);
  }
  std::fprintf(stderr, "\rbare Embree loops...   ");
  // Two yardsticks: single rays (rtcIntersect1) and 16-wide packets (rtcIntersect16), the
  // latter being what the full frame uses by default.
  uint64_t bareSegments = 0, packetSegments = 0;
  double bareSeconds = 0.0, packetSeconds = 0.0;
  for (int f = 0; f < c.frames; ++f) {
    const bench::BareResult b = bench::traceBare(sim.geometry(), scene.sources[0].position,
                                                 s.raysPerFrame, s.maxOrder, s.threads, f);
    bareSegments += b.segments;
    bareSeconds += b.seconds;
    const bench::BareResult p =
        bench::traceBare(sim.geometry(), scene.sources[0].position, s.raysPerFrame, s.maxOrder,
                         s.threads, f, bench::BareMode::kPacket16);
    packetSegments += p.segments;
    packetSeconds += p.seconds;
  }
  std::fprintf(stderr, "\r                      \r");
  const double fullRate = double(segments) / traceSeconds;
  const double bareRate = double(bareSegments) / bareSeconds;
  const double packetRate = double(packetSegments) / packetSeconds;
  json j;
  j["benchmark"] = "propagation";
  j["scene"] = c.scene;
  j["triangles"] = sim.geometry().triangleCount();
  j["threads"] = s.threads;
  j["rays_per_frame"] = s.raysPerFrame;
  j["max_order"] = s.maxOrder;
  j["roulette"] = s.rouletteThreshold > 0.f;
  j["estimator"] = s.estimator == Estimator::kDpc ? "dpc" : "path_tracing";
  j["tau_s"] = s.cacheTau;
  j["frames"] = c.frames;
  j["full_frame"] = {{"segments_per_second", fullRate},
                     {"segments_per_frame", double(segments) / c.frames},
                     {"listener_hits_per_frame", double(hits) / c.frames},
                     {"frame_ms", stats(frameMs)},
                     {"trace_ms", stats(traceMs)},
                     {"estimator_ms", stats(estimatorMs)}};
  j["bare_embree"] = {{"segments_per_second", bareRate},
                      {"segments_per_frame", double(bareSegments) / c.frames},
                      {"note", "same rays and max order, cosine bounces, no listener/cache"}};
  j["bare_embree_packet16"] = {{"segments_per_second", packetRate},
                               {"segments_per_frame", double(packetSegments) / c.frames}};
  j["ratio_full_to_bare"] = fullRate / bareRate;
  j["ratio_full_to_bare_packet16"] = fullRate / packetRate;
  const Simulation::SourceResult& r0 = sim.result(0);
  j["cache"] = {{"entries", r0.cacheEntries},
                {"bytes", r0.cacheBytes},
                {"budget_bytes", r0.cacheBudgetBytes},
                {"coarse_entries", r0.cacheCoarseEntries},
                {"entries_merged", r0.cacheMergedEntries},
                {"merged_energy_fraction", r0.cacheCoarseEnergyFraction}};
  j["ir_synthesis_ms"] = stats(synthMs);
  j["ir_samples"] = synth.lengthSamples();
  // Binaural IR synthesis (target: <= 10 ms per source per frame for a 2 s IR at
  // 48 kHz, 4096 rays per frame, one core): a directional frame, then the synthesis timed.
  {
    SceneDesc binaural = scene;
    binaural.audio.output = OutputFormat::kBinaural;
    PropagationSettings bs = s;
    bs.irLength = 2.0f;
    bs.raysPerFrame = 4096;
    Simulation dsim(binaural, bs);
    dsim.enableDirectional(defaultSpatialDirections());
    auto spatial = makeSpatialSynthesizer(binaural, bs, roomVolume(binaural.mesh));
    std::vector<float> left(spatial->lengthSamples()), right(spatial->lengthSamples());
    std::vector<double> ms;
    for (int f = 0; f < std::max(5, c.frames / 3); ++f) {
      dsim.runFrame(listener);
      const auto t0 = std::chrono::steady_clock::now();
      spatial->synthesize(dsim.directional(0), dsim.result(0).direct, left.data(), right.data());
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    j["binaural_ir_synthesis_ms"] = stats(ms);
    j["binaural_ir"] = {{"seconds", 2.0},
                        {"directions", spatial->directions().size()},
                        {"rays_per_frame", 4096},
                        {"threads", 1}};
  }
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}

/// Listener path for the noise study: the scene's trajectory (or +x from its position)
/// walked at `speed` m/s, sampled at frame f of a rate of `frameRate`.
std::function<glm::vec3(int)> walker(const SceneDesc& scene, double speed, double frameRate) {
  std::vector<glm::vec3> pts;
  for (const Keyframe& k : scene.listeners[0].trajectory) pts.push_back(k.position);
  if (pts.size() < 2) {
    const glm::vec3 p = listenerPositionAt(scene.listeners[0], 0.0);
    pts = {p, p + glm::vec3(100.f, 0.f, 0.f)};
  }
  return [pts, speed, frameRate](int f) {
    double d = speed * f / frameRate;
    for (size_t i = 0; i + 1 < pts.size(); ++i) {
      const double len = glm::length(pts[i + 1] - pts[i]);
      if (d <= len || i + 2 == pts.size())
        return pts[i] + (pts[i + 1] - pts[i]) * float(std::min(1.0, d / std::max(len, 1e-9)));
      d -= len;
    }
    return pts.back();
  };
}

int benchNoise(const Common& c, double walkSpeed, int referenceFrames, int warmup,
               const std::vector<int>& ptMultipliers) {
  const SceneDesc scene = firstSourceOnly(loadScene(c.scene));
  PropagationSettings s = settingsFor(scene, c);
  if (!c.haveRays) s.raysPerFrame = 4096;
  const auto at = walker(scene, walkSpeed, s.frameRate);
  const int total = warmup + c.frames;
  // Order ranges as delay ranges (mean reflection rate of the room, bench/noise_study.h).
  const std::vector<std::pair<int, int>> orderRanges = {{1, 3}, {4, 10}, {11, 50}, {51, 200}};
  std::vector<std::pair<double, double>> delayRanges;
  {
    const Geometry geometry(scene.mesh, scene.materials, s.patchSize, scene.objects);
    const double volume = roomVolume(scene.mesh);  // the room's, not its bounding box's
    const double direct = glm::length(scene.sources[0].position - at(0)) / double(s.speedOfSound);
    for (auto [d0, d1] : orderRanges)
      delayRanges.push_back(
          delayRangeOfOrders(d0, d1, volume, geometry.surfaceArea(), s.speedOfSound, direct));
  }
  // References: converged plain path tracing at each frame's position (one if static).
  std::vector<EnergyResponse> refs;
  std::vector<double> refErrors;
  std::vector<double> refRangeErrors(delayRanges.size(), 0.0);
  const int positions = walkSpeed > 0.0 ? total : 1;
  PropagationSettings refSettings = s;
  refSettings.seed = s.seed + 1000003;
  for (int f = 0; f < positions; ++f) {
    double e = 0.0;
    std::vector<double> byRange;
    refs.push_back(referenceResponse(scene, refSettings, at(f), referenceFrames, &e, 0,
                                     &delayRanges, &byRange));
    refErrors.push_back(e);
    for (size_t r = 0; r < byRange.size(); ++r) refRangeErrors[r] += byRange[r] / positions;
    std::fprintf(stderr, "\rreference %d/%d", f + 1, positions);
  }
  const double refError =
      std::accumulate(refErrors.begin(), refErrors.end(), 0.0) / double(refErrors.size());
  auto ref = [&](int f) -> const EnergyResponse& { return refs[walkSpeed > 0.0 ? size_t(f) : 0]; };
  // The reference's own error adds in quadrature to an estimator's error against it.
  auto correctedBy = [](double e, double r) { return std::sqrt(std::max(0.0, e * e - r * r)); };
  auto corrected = [&](double e) { return correctedBy(e, refError); };
  auto describe = [&](const NoiseMetrics& m) {
    return json{
        {"error", m.meanError},        {"error_corrected_for_reference", corrected(m.meanError)},
        {"flicker", m.meanFlicker},    {"bias", m.bias},
        {"energy_bias", m.energyBias}, {"error_per_frame", m.errorPerFrame}};
  };
  json j;
  j["benchmark"] = "noise";
  j["scene"] = c.scene;
  j["rays_per_frame"] = s.raysPerFrame;
  j["max_order"] = s.maxOrder;
  j["tau_s"] = s.cacheTau;
  j["frame_rate"] = s.frameRate;
  j["walk_speed_mps"] = walkSpeed;
  j["frames_measured"] = c.frames;
  j["warmup_frames"] = warmup;
  auto rangeName = [&](size_t r) {
    return std::to_string(orderRanges[r].first) + "-" + std::to_string(orderRanges[r].second);
  };
  json refByRange;
  for (size_t r = 0; r < delayRanges.size(); ++r) refByRange[rangeName(r)] = refRangeErrors[r];
  j["reference"] = {{"frames", referenceFrames},
                    {"rays", double(referenceFrames) * s.raysPerFrame},
                    {"own_relative_error", refError},
                    {"own_relative_error_by_order", refByRange}};
  j["metric"] =
      "L2 over 8 bands x 10 ms bins of the energy response, relative to the reference's L2 norm";
  std::map<std::string, double> dpcError;
  std::map<std::string, std::vector<double>> dpcRangeError;
  std::map<std::string, std::vector<double>> dpcEnergy;
  for (auto [name, weighting] :
       {std::pair{"dpc_window", DpcWeighting::kWindow}, std::pair{"dpc_ema", DpcWeighting::kEma},
        std::pair{"dpc_seed", DpcWeighting::kSeed}}) {
    PropagationSettings d = s;
    d.estimator = Estimator::kDpc;
    d.dpcWeighting = weighting;
    std::fprintf(stderr, "\r%s...            ", name);
    const NoiseMetrics m = measureNoise(scene, d, warmup, c.frames, at, ref, 0, nullptr, delayRanges);
    j["estimators"][name] = describe(m);
    dpcEnergy[name] = m.energyPerFrame;
    dpcError[name] = corrected(m.meanError);
    for (size_t r = 0; r < m.errorByRange.size(); ++r)
      dpcRangeError[name].push_back(correctedBy(m.errorByRange[r], refRangeErrors[r]));
  }
  // The estimator's own bias, free of Monte Carlo error: path tracing with the same seed traces
  // the same rays in every frame, so the window's total energy at frame f must equal the mean
  // of path tracing's over the frames in its window (all frames so far, at most W), and the
  // EMA's the same exponential average of them, up to float rounding (and the coarse store's
  // rounding when the budget is hit).
  {
    PropagationSettings p = s;
    p.estimator = Estimator::kPathTracing;
    const NoiseMetrics m = measureNoise(scene, p, warmup, c.frames, at, ref, 0, nullptr, {});
    const std::vector<double> window =
        cacheAveraged(m.energyPerFrame, DpcWeighting::kWindow, s.cacheTau, s.frameRate);
    const std::vector<double> ema =
        cacheAveraged(m.energyPerFrame, DpcWeighting::kEma, s.cacheTau, s.frameRate);
    double sumWindow = 0.0, sumEma = 0.0, sumPtWindow = 0.0, sumPtEma = 0.0;
    for (size_t f = size_t(warmup); f < window.size(); ++f) {
      sumPtWindow += window[f];
      sumPtEma += ema[f];
      sumWindow += dpcEnergy["dpc_window"][f];
      sumEma += dpcEnergy["dpc_ema"][f];
    }
    j["energy_bias_vs_same_rays"] = {
        {"dpc_window", sumWindow / sumPtWindow - 1.0},
        {"dpc_ema", sumEma / sumPtEma - 1.0},
        {"note",
         "total energy over the measured frames against path tracing of the same rays, "
         "averaged as the estimator averages (window: mean of the last W frames; ema: "
         "exponential); free of Monte Carlo error, so it isolates the estimator's own bias"}};
  }
  // Plain path tracing at 1x, 2x, 4x ... the rays: error ~ rays^-1/2.
  std::vector<std::pair<double, double>> pt;  // (multiplier, corrected error)
  std::vector<std::vector<std::pair<double, double>>> ptRange(delayRanges.size());
  for (int k : ptMultipliers) {
    PropagationSettings p = s;
    p.estimator = Estimator::kPathTracing;
    p.raysPerFrame = s.raysPerFrame * k;
    std::fprintf(stderr, "\rpath tracing x%d...     ", k);
    const NoiseMetrics m =
        measureNoise(scene, p, 0, std::min(c.frames, 20), at, ref, 0, nullptr, delayRanges);
    j["path_tracing"][std::to_string(k) + "x"] = describe(m);
    pt.push_back({double(k), corrected(m.meanError)});
    for (size_t r = 0; r < delayRanges.size(); ++r)
      ptRange[r].push_back({double(k), correctedBy(m.errorByRange[r], refRangeErrors[r])});
  }
  std::fprintf(stderr, "\r                         \r");
  // Equal-noise ray ratio: interpolate log(error) against log(rays) between the bracketing
  // path-tracing runs, or extrapolate along the last two with their fitted slope.
  auto equalNoise = [](const std::vector<std::pair<double, double>>& pt, double dpcError,
                       std::string* how) {
    double ratio = NAN;
    if (how) *how = "interpolated";
    for (size_t i = 0; i + 1 < pt.size(); ++i)
      if (pt[i].second >= dpcError && pt[i + 1].second <= dpcError && dpcError > 0.0) {
        const double t =
            std::log(pt[i].second / dpcError) / std::log(pt[i].second / pt[i + 1].second);
        ratio = std::exp(std::log(pt[i].first) + t * std::log(pt[i + 1].first / pt[i].first));
      }
    if (std::isnan(ratio) && pt.size() >= 2 && dpcError > 0.0) {
      const auto& a = pt[pt.size() - 2];
      const auto& b = pt.back();
      const double slope = std::log(b.second / a.second) / std::log(b.first / a.first);
      ratio = b.first * std::pow(dpcError / b.second, 1.0 / slope);
      if (how) *how = "extrapolated with slope " + std::to_string(slope);
    }
    return ratio;
  };
  std::string how;
  const double ratio = equalNoise(pt, dpcError["dpc_ema"], &how);
  std::string howWindow;
  const double ratioWindow = equalNoise(pt, dpcError["dpc_window"], &howWindow);
  json byOrder;
  for (size_t r = 0; r < delayRanges.size(); ++r) {
    byOrder[rangeName(r)] = equalNoise(ptRange[r], dpcRangeError["dpc_window"][r], nullptr);
    j["order_ranges_as_delays_s"][rangeName(r)] = {delayRanges[r].first, delayRanges[r].second};
  }
  j["equal_noise_ray_ratio_by_order"] = byOrder;
  j["equal_noise_ray_ratio_by_order_estimator"] = "dpc_window (the default)";
  j["energy_bias"] = j["estimators"]["dpc_window"]["energy_bias"];
  j["energy_bias_note"] =
      "dpc_window's total energy over the measured frames vs the reference, signed; the "
      "reference's own relative error is reference.own_relative_error";
  j["equal_noise_ray_ratio"] = {
      {"dpc_ema", ratio}, {"how", how}, {"dpc_window", ratioWindow}, {"how_window", howWindow}};
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}

int benchLive(const Common& c, double duration, int blockSize, double frameRate,
              const std::string& device) {
  const auto shared = std::make_shared<SceneDesc>(loadScene(c.scene));
  SceneDesc& scene = *shared;
  scene.audio.blockSize = blockSize;
  PropagationSettings s = settingsFor(scene, c);
  if (frameRate > 0.0) s.frameRate = float(frameRate);
  LiveSession::Options lo;
  lo.deviceChannels = 2;
  LiveSession session(shared, s, std::make_shared<const DrySignals>(loadDrySignals(scene)), lo);
  session.setPose(listenerPositionAt(scene.listeners[0], 0.0), 0.f, 0.0);
  std::unique_ptr<NullOutput> null;
  std::unique_ptr<audio::AudioOutput> real;
  if (device.empty()) {
    null = std::make_unique<NullOutput>(scene.audio.sampleRate, blockSize, 2,
                                        &LiveSession::renderCallback, &session);
  } else {
    audio::AudioOutput::Options ao;
    ao.device = device;
    ao.sampleRate = scene.audio.sampleRate;
    ao.channels = 2;
    ao.blockSize = blockSize;
    real = std::make_unique<audio::AudioOutput>(ao, &LiveSession::renderCallback, &session);
  }
  session.start();
  if (null)
    null->start();
  else
    real->start();
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (t >= duration) break;
    session.setPose(listenerPositionAt(scene.listeners[0], t), 0.f, t);  // walking: every 5 ms
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (null)
    null->stop();
  else
    real->stop();
  session.stop();
  const double periodNs = 1e9 * blockSize / scene.audio.sampleRate;
  auto pct = [&](const audio::CallbackStats& st) {
    const auto snap = st.snapshot();
    return json{{"blocks", snap.callbacks},
                {"median_pct", 100.0 * double(snap.quantileNs(0.5)) / periodNs},
                {"p999_pct", 100.0 * double(snap.quantileNs(0.999)) / periodNs},
                {"max_pct", 100.0 * double(snap.maxNs) / periodNs}};
  };
  const auto lat = session.latencyStats().snapshot();
  const LiveSession::Status st = session.status();
  const auto cb = null ? null->stats().snapshot() : real->stats().snapshot();
  json j;
  j["benchmark"] = "live";
  j["scene"] = c.scene;
  j["device"] = device.empty() ? "null (timer thread at the block rate)" : device;
  j["sample_rate"] = scene.audio.sampleRate;
  j["block_size"] = blockSize;
  j["block_period_ms"] = periodNs * 1e-6;
  j["rays_per_frame"] = s.raysPerFrame;
  // Adaptive rays (docs/live.md): what the controller traced to hold the frame rate.
  j["rays_per_frame_last"] = st.raysPerFrame;
  j["rays_per_frame_min"] = st.raysPerFrameMin;
  j["reduced_frames"] = st.reducedFrames;
  j["frame_rate_target"] = s.frameRate;
  j["threads"] = s.threads;
  j["duration_s"] = duration;
  j["frames"] = st.frames;
  j["frames_per_second"] = double(st.frames) / duration;
  j["irs_applied"] = st.irsApplied;
  j["motion_to_sound_latency_ms"] = {{"samples", lat.callbacks},
                                     {"median", double(lat.quantileNs(0.5)) * 1e-6},
                                     {"p95", double(lat.quantileNs(0.95)) * 1e-6},
                                     {"max", double(lat.maxNs) * 1e-6}};
  j["render_time_with_ir_swap"] = pct(session.renderStatsWithSwap());
  j["render_time_without_ir_swap"] = pct(session.renderStatsWithoutSwap());
  j["callbacks"] = cb.callbacks;
  j["xruns"] = cb.xruns;
  j["nan_blocks"] = st.nanBlocks;
  j["note"] =
      "latency: pose published by the control thread -> first block rendered with an "
      "IR computed for that pose; render time: LiveSession::render per block, % of the "
      "block period";
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}
/// Frame time for several listeners traced in one pass (docs/dynamic.md, "Several
/// listeners"): one PropagationStage per listener count, stepped frame by frame in turn (so
/// that load from other processes falls on all counts alike); wall-clock frame time and process
/// CPU time of the pass (tracing + one cache per source-listener pair) and CPU time of
/// preparing every listener's IR set.
int benchListeners(const Common& c, const std::vector<int>& counts, int warmupFrames) {
  const auto shared = std::make_shared<const SceneDesc>(loadScene(c.scene));
  const SceneDesc& scene = *shared;
  PropagationSettings s = settingsFor(scene, c);
  auto cpu = [] { return double(std::clock()) / CLOCKS_PER_SEC; };
  auto wall = [] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  };
  // Listener i: scene listener i mod n, at a point of its trajectory spread over its span.
  const size_t n = scene.listeners.size();
  auto place = [&](size_t i, size_t count, double t, WorldState& w) {
    const ListenerDesc& d = scene.listeners[i % n];
    const double span = d.trajectory.size() > 1
                            ? d.trajectory.back().timeSeconds - d.trajectory.front().timeSeconds
                            : 0.0;
    const size_t per = (count + n - 1) / n;
    const double ti = t + span * double(i / n) / double(per);
    w.listenerPositions[i] = listenerPositionAt(d, ti);
    w.listenerOrientations[i] = listenerOrientationAt(d, ti);
  };
  std::vector<std::unique_ptr<PropagationStage>> stages;
  const int maxCount = *std::max_element(counts.begin(), counts.end());
  for (size_t k = 0; k < counts.size(); ++k)
    stages.push_back(std::make_unique<PropagationStage>(shared, s, 3 * maxCount + 1));
  std::vector<double> traceCpu(counts.size(), 0.0), prepareCpu(counts.size(), 0.0);
  std::vector<double> traceWall(counts.size(), 0.0);
  std::vector<uint64_t> segments(counts.size(), 0), hits(counts.size(), 0);
  WorldState world;
  for (int f = -warmupFrames; f < c.frames; ++f) {
    const double t = double(f + warmupFrames) / s.frameRate;
    if (f == 0) {  // steady state from here: caches filled, their memory touched
      std::fill(traceCpu.begin(), traceCpu.end(), 0.0);
      std::fill(traceWall.begin(), traceWall.end(), 0.0);
      std::fill(prepareCpu.begin(), prepareCpu.end(), 0.0);
      std::fill(segments.begin(), segments.end(), 0);
      std::fill(hits.begin(), hits.end(), 0);
    }
    for (size_t k = 0; k < counts.size(); ++k) {
      evaluateWorld(scene, t, world);
      const size_t count = size_t(counts[k]);
      world.listenerPositions.resize(count);
      world.listenerOrientations.resize(count);
      for (size_t i = 0; i < count; ++i) place(i, count, t, world);
      double t0 = cpu();
      const double w0 = wall();
      stages[k]->traceWorld(world);
      traceWall[k] += wall() - w0;
      traceCpu[k] += cpu() - t0;
      t0 = cpu();
      for (size_t l = 0; l < count; ++l) stages[k]->recycle(stages[k]->prepare(l));
      prepareCpu[k] += cpu() - t0;
      for (size_t src = 0; src < scene.sources.size(); ++src) {
        segments[k] += stages[k]->simulation().result(src).trace.segments;
        hits[k] += stages[k]->simulation().result(src).trace.listenerHits;
      }
    }
    std::fprintf(stderr, "\rframe %d/%d", f + warmupFrames + 1, c.frames + warmupFrames);
  }
  std::fprintf(stderr, "\n");
  json j;
  j["warmup_frames"] = warmupFrames;
  j["machine"] = "shared 2-core machine under load from other builds: ratios within one run";
  j["scene"] = c.scene;
  j["sources"] = scene.sources.size();
  j["rays_per_frame"] = s.raysPerFrame;
  j["frames"] = c.frames;
  j["estimator"] = s.estimator == Estimator::kDpc ? "dpc" : "path_tracing";
  json rows = json::array();
  for (size_t k = 0; k < counts.size(); ++k) {
    json e;
    e["listeners"] = counts[k];
    e["pass_wall_ms_per_frame"] = 1e3 * traceWall[k] / c.frames;
    e["pass_wall_ratio_to_one"] = traceWall[k] / traceWall[0];
    e["pass_cpu_ms_per_frame"] = 1e3 * traceCpu[k] / c.frames;
    e["prepare_all_cpu_ms_per_frame"] = 1e3 * prepareCpu[k] / c.frames;
    e["pass_ratio_to_one"] = traceCpu[k] / traceCpu[0];
    e["segments_per_frame"] = double(segments[k]) / c.frames;
    e["sphere_hits_per_frame"] = double(hits[k]) / c.frames;
    rows.push_back(e);
    std::fprintf(stderr,
                 "%d listeners: pass wall %.1f ms (x%.2f), CPU %.1f ms (x%.2f), prepare all "
                 "%.1f ms, segments %.0f\n",
                 counts[k], 1e3 * traceWall[k] / c.frames, traceWall[k] / traceWall[0],
                 1e3 * traceCpu[k] / c.frames, traceCpu[k] / traceCpu[0],
                 1e3 * prepareCpu[k] / c.frames, double(segments[k]) / c.frames);
  }
  j["listeners"] = rows;
  j["note"] =
      "pass: one traceWorld (every source's rays traced once against all listener spheres, "
      "then each source-listener pair's cache); prepare all: IR synthesis + partition/FFT for "
      "every listener (offline needs all, live only the played one); wall-clock frame time "
      "(what the frame rate sees) and process CPU time of the frames after warmup_frames (the "
      "first frames fill the caches and fault in their memory)";
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}

/// Door step response, static noise and moving-object frame time (docs/dynamic.md).
int benchDynamic(int rays, int frames, const std::string& parts) {
  auto want = [&](const char* part) { return parts.find(part) != std::string::npos; };
  json j;
  j["machine"] = "shared 2-core machine under load from other builds: ratios within one run";
  j["scene"] = "two rooms 10 x 3 x 4 m, 1 x 2 m doorway, door shut/open by pose jumps";
  j["rays_per_frame"] = rays;
  json steps = json::array();
  const std::pair<const char*, DpcWeighting> weightings[] = {{"ema", DpcWeighting::kEma},
                                                             {"seed", DpcWeighting::kSeed},
                                                             {"window", DpcWeighting::kWindow}};
  for (const auto& [name, w] : weightings) {
    if (!want("step")) break;
    for (double tau : {0.25, 0.5, 1.0, 2.0}) {
      // "ema_matched": the EMA with the time constant that completes 90 % of a step at tau
      // (1 - exp(-tau / tau_e) = 0.9, tau_e = tau / ln 10), for the noise comparison.
      for (bool matched : {false, true}) {
        if (matched && w != DpcWeighting::kEma) continue;
        const double tauE = matched ? tau / std::log(10.0) : tau;
        SceneDesc sc = test::twoRooms(w, float(tauE));
        sc.propagation.raysPerFrame = rays;
        Simulation sim(sc);
        const glm::vec3 L = sc.listeners[0].position;
        const double T = 1.0 / sc.propagation.frameRate;
        const int settle = int(std::ceil(std::max(3.0 * tau, 1.5) / T));
        const int span = int(std::ceil(3.0 * tau / T));
        auto late = [&] { return double(sim.result(0).energy.total()[3]); };
        sim.setObjectPoses({test::kDoorOpen});
        for (int f = 0; f < settle; ++f) sim.runFrame(L);
        std::vector<double> open;
        for (int f = 0; f < span; ++f) sim.runFrame(L), open.push_back(late());
        const double openMean = std::accumulate(open.begin(), open.end(), 0.0) / double(span);
        double var = 0.0;
        for (double x : open) var += (x - openMean) * (x - openMean);
        const double openSd = std::sqrt(var / double(span - 1));
        std::vector<double> shut, reopen;
        sim.setObjectPoses({test::kDoorShut});
        for (int f = 0; f < span; ++f) sim.runFrame(L), shut.push_back(late());
        sim.setObjectPoses({test::kDoorOpen});
        for (int f = 0; f < span; ++f) sim.runFrame(L), reopen.push_back(late());
        const double shutLevel = shut.back();
        // Time of the frame after the change (0 = the first frame with the new pose) from
        // which the readout has completed 90 % of the step; frame k is at k T after the change.
        auto t90 = [&](const std::vector<double>& v, bool down) {
          for (size_t k = 0; k < v.size(); ++k) {
            const double done = down ? (openMean - v[k]) / (openMean - shutLevel)
                                     : (v[k] - shutLevel) / (openMean - shutLevel);
            if (done >= 0.9) return double(k) * T;
          }
          return std::nan("");
        };
        json e;
        e["weighting"] = matched ? "ema_matched" : name;
        e["tau"] = tau;
        e["time_constant"] = tauE;
        e["open_level"] = openMean;
        e["open_relative_sd"] = openSd / openMean;
        e["t90_shut"] = t90(shut, true);
        e["t90_open"] = t90(reopen, false);
        e["frame_period"] = T;
        e["shut"] = shut;
        e["reopen"] = reopen;
        steps.push_back(e);
        std::fprintf(stderr, "%s tau %.2f: t90 shut %.2f open %.2f, sd %.3f\n",
                     matched ? "ema_matched" : name, tau, double(e["t90_shut"]),
                     double(e["t90_open"]), openSd / openMean);
      }
    }
  }
  j["step_response"] = steps;

  // Frame time with N moving objects vs the same triangles baked into the static mesh.
  json objs = json::array();
  for (int n : {1, 10, 100}) {
    if (!want("objects")) break;
    SceneDesc moving = test::makeShoebox({20, 5, 20}, Bands(0.2f), 0.5f, {3, 2, 3}, {15, 2, 15});
    moving.propagation.estimator = Estimator::kPathTracing;
    moving.propagation.raysPerFrame = rays;
    moving.propagation.maxOrder = 30;
    SceneDesc baked = moving;
    for (int k = 0; k < n; ++k) {
      ObjectDesc o;
      o.name = "panel" + std::to_string(k);
      test::addPanel(o.mesh, {0, 0, 0}, {0.5f, 0, 0}, {0, 1, 0}, 0);
      ObjectKeyframe key;
      key.position = {1.f + float(k % 10) * 1.8f, 0.5f + float(k / 50),
                      1.f + float(k / 10 % 5) * 3.6f};
      o.trajectory = {key};
      for (glm::vec3 v : o.mesh.vertices) baked.mesh.vertices.push_back(v + key.position);
      const auto base = uint32_t(baked.mesh.vertices.size() - 4);
      for (const auto& t : o.mesh.triangles) {
        baked.mesh.triangles.push_back({base + t[0] - 0, base + t[1], base + t[2]});
        baked.mesh.materialIndex.push_back(0);
      }
      moving.objects.push_back(o);
    }
    Simulation sm(moving), sb(baked);
    std::vector<Pose> poses(static_cast<size_t>(n));
    auto cpu = [] { return double(std::clock()) / CLOCKS_PER_SEC; };
    double movingCpu = 0.0, staticCpu = 0.0;
    for (int f = 0; f < frames; ++f) {
      for (int k = 0; k < n; ++k) {
        const ObjectKeyframe& key = moving.objects[size_t(k)].trajectory[0];
        poses[size_t(k)] = Pose{key.position + glm::vec3(0.f, 0.f, 0.01f * float(f % 7)),
                                glm::angleAxis(0.05f * float(f), glm::vec3(0, 1, 0))};
      }
      double t0 = cpu();
      sm.setObjectPoses(poses);
      sm.runFrame(moving.listeners[0].position);
      movingCpu += cpu() - t0;
      t0 = cpu();
      sb.runFrame(baked.listeners[0].position);
      staticCpu += cpu() - t0;
    }
    json e;
    e["objects"] = n;
    e["triangles"] = sb.geometry().triangleCount();
    e["moving_cpu_ms_per_frame"] = 1e3 * movingCpu / frames;
    e["static_cpu_ms_per_frame"] = 1e3 * staticCpu / frames;
    e["ratio"] = movingCpu / staticCpu;
    objs.push_back(e);
    std::fprintf(stderr, "%d objects: moving/static cpu %.3f\n", n, movingCpu / staticCpu);
  }
  j["moving_objects"] = objs;

  // Noise while a source walks at 1.5 m/s vs standing still: relative RMS error of each frame's
  // energy response (10 ms bins, all bands; bench/noise_study.h) against converged path
  // tracing at that frame's source position; path tracing and the DPC window (tau 0.5 s) with
  // the same seed, i.e. the same rays.
  if (want("moving_source")) {
    SceneDesc room = test::makeShoebox({10, 3, 7}, Bands(0.15f), 0.5f, {2, 1.6f, 2}, {8, 1.6f, 5});
    room.propagation.raysPerFrame = rays;
    room.propagation.frameRate = 10.f;
    room.propagation.cacheTau = 0.5f;
    const double T = 1.0 / room.propagation.frameRate, speed = 1.5;
    const int warm = int(std::lround(room.propagation.cacheTau / T)), measured = 25;
    const int total = warm + measured;
    auto sourceAt = [&](int f) {
      return room.sources[0].position + glm::vec3(float(speed * T * f), 0.f, 0.f);
    };
    PropagationSettings refSettings = room.propagation;
    refSettings.raysPerFrame = 4 * rays;
    refSettings.seed += 1000003;
    std::vector<EnergyResponse> refs;
    double refError = 0.0;
    for (int f = 0; f < total; ++f) {
      SceneDesc at = room;
      at.sources[0].position = sourceAt(f);
      double e = 0.0;
      refs.push_back(referenceResponse(at, refSettings, room.listeners[0].position, 16, &e));
      refError = std::max(refError, e);
      std::fprintf(stderr, "\rmoving-source references %d/%d", f + 1, total);
    }
    std::fprintf(stderr, "\n");
    const EnergyResponse staticRef = refs.front();
    json cases = json::array();
    for (bool moving : {true, false})
      for (Estimator est : {Estimator::kPathTracing, Estimator::kDpc}) {
        PropagationSettings ps = room.propagation;
        ps.estimator = est;
        const NoiseMetrics m = measureNoise(
            room, ps, warm, measured, [&](int) { return room.listeners[0].position; },
            [&](int f) -> const EnergyResponse& { return moving ? refs[size_t(f)] : staticRef; }, 0,
            moving ? std::function<glm::vec3(int)>(sourceAt) : nullptr);
        json e;
        e["estimator"] = est == Estimator::kDpc ? "dpc_window" : "path_tracing";
        e["source"] = moving ? "walking" : "static";
        e["mean_error"] = m.meanError;
        e["mean_flicker"] = m.meanFlicker;
        e["error_per_frame"] = m.errorPerFrame;
        cases.push_back(e);
        std::fprintf(stderr, "%s %s: error %.3f flicker %.3f\n", moving ? "walking" : "static",
                     est == Estimator::kDpc ? "window" : "path tracing", m.meanError,
                     m.meanFlicker);
      }
    json ms;
    ms["scene"] = "shoebox 10 x 3 x 7 m, absorption 0.15, scattering 0.5";
    ms["speed_m_per_s"] = speed;
    ms["tau"] = room.propagation.cacheTau;
    ms["frame_period"] = T;
    ms["warmup_frames"] = warm;
    ms["reference_relative_error"] = refError;
    ms["cases"] = cases;
    j["moving_source"] = ms;
  }
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}

/// Memory budget sweep (docs/estimators.md): for each rays-per-frame value, the DPC at the
/// budget and an unbounded one (16384 MB, pages committed only as used) see the same rays; the
/// JSON gives entries, bytes, merged entries, the coarse store's share and the budget's bias
/// (total energy and strength G of the last frame, budgeted vs unbounded).
int benchBudget(const Common& c, const std::vector<int>& raysList) {
  SceneDesc scene;
  if (c.scene == "room-4x3x2.5")
    scene = test::makeShoebox({4, 3, 2.5f}, Bands(0.1f), 1.f, {1, 1, 1.2f}, {3, 2, 1.5f});
  else
    scene = firstSourceOnly(loadScene(c.scene));
  PropagationSettings s = settingsFor(scene, c);
  s.estimator = Estimator::kDpc;
  s.diffraction = false;
  const int frames = std::max(1, c.frames);
  json j;
  j["benchmark"] = "budget";
  j["scene"] = c.scene;
  j["budget_mb"] = s.cacheMemoryMb;
  j["weighting"] = s.dpcWeighting == DpcWeighting::kWindow ? "window"
                   : s.dpcWeighting == DpcWeighting::kEma  ? "ema"
                                                           : "seed";
  j["tau_s"] = s.cacheTau;
  j["frames"] = frames;
  json points = json::array();
  for (int rays : raysList) {
    PropagationSettings a = s, b = s;
    a.raysPerFrame = b.raysPerFrame = rays;
    b.cacheMemoryMb = 16384.f;
    Simulation small(scene, a), big(scene, b);
    size_t maxBytes = 0;
    const glm::vec3 at = listenerPositionAt(scene.listeners[0], 0.0);
    for (int f = 0; f < frames; ++f) {
      small.runFrame(at);
      big.runFrame(at);
      maxBytes = std::max(maxBytes, small.result(0).cacheBytes);
    }
    const auto& x = small.result(0);
    const auto& y = big.result(0);
    const double ex = x.energy.total().average(), ey = y.energy.total().average();
    json p;
    p["rays_per_frame"] = rays;
    p["entries"] = x.cacheEntries;
    p["coarse_entries"] = x.cacheCoarseEntries;
    p["bytes"] = maxBytes;
    p["budget_bytes"] = x.cacheBudgetBytes;
    p["entries_merged"] = x.cacheMergedEntries;
    p["merged_energy_fraction"] = x.cacheCoarseEnergyFraction;
    p["unbounded_entries"] = y.cacheEntries;
    p["energy_ratio_vs_unbounded"] = ey > 0.0 ? ex / ey : 1.0;
    p["g_difference_db"] = ey > 0.0 ? 10.0 * std::log10(ex / ey) : 0.0;
    points.push_back(p);
    std::fprintf(stderr, "%d rays: entries %zu (unbounded %zu), merged %llu, energy ratio %.6f\n",
                 rays, x.cacheEntries, y.cacheEntries, (unsigned long long)x.cacheMergedEntries,
                 ex / ey);
  }
  j["points"] = points;
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}
/// Edge diffraction cost (docs/validation.md): load-time edge finding, then per source-listener
/// pair and frame the direct sound plus EdgeDiffraction::apply (one thread), at F listener
/// positions spread over the scene's listener's trajectory (its last keyframe's time, or 20 s).
int benchDiffraction(const Common& c) {
  using Clock = std::chrono::steady_clock;
  const SceneDesc scene = loadScene(c.scene);
  const PropagationSettings s = settingsFor(scene, c);
  const auto t0 = Clock::now();
  const Geometry geometry(scene.mesh, scene.materials, s.patchSize, scene.objects);
  const auto t1 = Clock::now();
  const EdgeDiffraction diffraction(scene.mesh);
  const auto t2 = Clock::now();
  const Propagator propagator(geometry, s);
  const ListenerDesc& listener = scene.listeners[0];
  const double span = listener.trajectory.empty() ? 20.0 : listener.trajectory.back().timeSeconds;
  const int frames = std::max(1, c.frames);
  std::vector<double> micros;
  double paths = 0.0;
  for (int f = 0; f < frames; ++f) {
    const double t = span * (f + 0.5) / frames;
    const ListenerSphere sphere{listenerPositionAt(listener, t), listener.radius};
    for (const SourceDesc& source : scene.sources) {
      const glm::vec3 at = sourcePositionAt(source, t);
      const auto a = Clock::now();
      DirectSound d = propagator.directSound(at, sphere);
      paths += double(diffraction.apply(geometry, at, sphere, s.speedOfSound,
                                        propagator.airAttenuationPerMetre(), d));
      micros.push_back(std::chrono::duration<double, std::micro>(Clock::now() - a).count());
    }
  }
  json j;
  j["benchmark"] = "diffraction";
  j["scene"] = c.scene;
  j["triangles"] = scene.mesh.triangles.size();
  j["candidate_edges"] = diffraction.edges().size();
  j["geometry_build_ms"] = std::chrono::duration<double, std::milli>(t1 - t0).count();
  j["edge_finding_ms"] = std::chrono::duration<double, std::milli>(t2 - t1).count();
  j["pairs_timed"] = micros.size();
  j["edge_paths_per_pair_mean"] = paths / double(micros.size());
  j["direct_plus_diffraction_us_per_pair"] = stats(micros);
  std::fprintf(stderr, "%zu edges; %.1f edge paths and %.0f us per pair (median)\n",
               diffraction.edges().size(), paths / double(micros.size()),
               percentile(micros, 0.5));
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dpc-bench: propagation speed and DPC noise benchmarks (JSON on stdout)"};
  app.require_subcommand(1);
  Common c;
  bool noRoulette = false;
  double walkSpeed = 0.0;
  int referenceFrames = 256, warmup = -1;
  std::vector<int> multipliers = {1, 2, 4, 8, 16, 32};
  auto addCommon = [&](CLI::App* sub) {
    sub->add_option("scene", c.scene, "Scene file")->required();
    sub->add_option("--threads", c.threads, "Tracing threads (0 = all cores)");
    sub->add_option("--rays", c.rays, "Rays per frame (default 4096)");
    sub->add_option("--max-order", c.maxOrder, "Maximum reflection order");
    sub->add_option("--frames", c.frames, "Frames to measure");
    sub->add_option("--tau", c.tau, "Cache response time tau, seconds");
    sub->add_option("--cache-memory-mb", c.cacheMb, "DPC memory budget per source, MB (> 0)")
        ->check(CLI::PositiveNumber);
  };
  CLI::App* prop = app.add_subcommand("propagation", "Frame time and segments/s vs bare Embree");
  addCommon(prop);
  prop->add_flag("--no-roulette", noRoulette, "Trace every ray to max order");
  CLI::App* noise =
      app.add_subcommand("noise", "DPC vs path tracing against a converged reference");
  addCommon(noise);
  noise->add_option("--walk-speed", walkSpeed, "Listener speed along the trajectory, m/s");
  noise->add_option("--reference-frames", referenceFrames, "Path-tracing frames per reference");
  noise->add_option("--warmup", warmup, "Frames before measuring (default 2 tau)");
  noise->add_option("--pt-multipliers", multipliers, "Ray multipliers for path tracing");
  CLI::App* live = app.add_subcommand("live", "Motion-to-sound latency and audio render load");
  double liveDuration = 20.0, liveFrameRate = 0.0;
  int liveBlock = 128;
  std::string liveDevice;
  addCommon(live);
  live->add_option("--duration", liveDuration, "Seconds to run (default 20)");
  live->add_option("--block-size", liveBlock, "Audio block size (default 128)");
  live->add_option("--frame-rate", liveFrameRate, "Propagation frames per second (default: scene)");
  live->add_option("--device", liveDevice, "Audio device (default: a timer thread, no device)");
  CLI::App* lis = app.add_subcommand(
      "listeners", "Frame time for several listeners traced in one pass (1, 2, 4, 8)");
  std::vector<int> listenerCounts = {1, 2, 4, 8};
  int listenerWarmup = 5;
  addCommon(lis);
  lis->add_option("--warmup-frames", listenerWarmup,
                  "Frames run before timing (cache fill, first-touch page faults; default 5)")
      ->check(CLI::Range(0, 1000));
  lis->add_option("--counts", listenerCounts, "Listener counts (first = the reference)")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  CLI::App* diff = app.add_subcommand(
      "diffraction", "Edge diffraction: edges found at load time, cost per source-listener pair");
  addCommon(diff);
  CLI::App* budget = app.add_subcommand(
      "budget", "Cache entries, bytes and budget bias vs rays per frame (scene or room-4x3x2.5)");
  std::vector<int> budgetRays = {1000, 10000, 100000};
  addCommon(budget);
  budget->add_option("--rays-list", budgetRays, "Rays per frame values");
  CLI::App* dyn = app.add_subcommand(
      "dynamic", "Door step response per estimator and tau; moving-object frame time");
  int dynRays = 2048, dynFrames = 20;
  std::string dynParts = "step,objects,moving_source";
  dyn->add_option("--parts", dynParts,
                  "Comma-separated parts to run: step, objects, moving_source (default all)");
  dyn->add_option("--rays", dynRays, "Rays per frame (default 2048)");
  dyn->add_option("--frames", dynFrames, "Frames per object-count measurement (default 20)");
  CLI::App* conv = app.add_subcommand(
      "convolve", "Convolver CPU: non-uniform dpc (with/without IR swaps) vs zita-convolver");
  bench::ConvolveOptions convOptions;
  conv->add_option("--blocks", convOptions.blocks, "Block sizes (default 64 128 256 512)")
      ->check(CLI::Range(16, 8192));
  conv->add_option("--seconds", convOptions.seconds, "Audio seconds per run (default 3)")
      ->check(CLI::Range(0.1, 600.0));
  conv->add_option("--swap-ms", convOptions.swapIntervalMs, "IR swap interval, ms (default 66)")
      ->check(CLI::Range(0.1, 10000.0));
  conv->add_flag("!--no-uniform", convOptions.uniform, "Skip the uniform convolver");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (CLI::App* sub : {prop, noise, live, lis, budget, diff}) {
    c.haveTau = c.haveTau || sub->count("--tau") > 0;
    c.haveCacheMb = c.haveCacheMb || sub->count("--cache-memory-mb") > 0;
    c.haveMaxOrder = c.haveMaxOrder || sub->count("--max-order") > 0;
    c.haveRays = c.haveRays || sub->count("--rays") > 0;
  }
  try {
    if (*prop) return benchPropagation(c, noRoulette);
    if (*dyn) return benchDynamic(dynRays, dynFrames, dynParts);
    if (*lis) return benchListeners(c, listenerCounts, listenerWarmup);
    if (*conv) return bench::benchConvolve(convOptions);
    if (*budget) return benchBudget(c, budgetRays);
    if (*diff) return benchDiffraction(c);
    if (*live) return benchLive(c, liveDuration, liveBlock, liveFrameRate, liveDevice);
    if (warmup < 0) {
      const SceneDesc scene = loadScene(c.scene);
      const double tau = c.haveTau ? c.tau : scene.propagation.cacheTau;
      warmup = int(std::ceil(2.0 * tau * scene.propagation.frameRate));
    }
    return benchNoise(c, walkSpeed, referenceFrames, warmup, multipliers);
  } catch (const InputError& e) {
    std::fprintf(stderr, "dpc-bench: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dpc-bench: error: %s\n", e.what());
    return 1;
  }
}
