// `dpc-bench live`: a live session on a device or a timer thread, its latency and load.
#include "bench/live_bench.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

#include "audio/audio_output.h"
#include "runtime/frame_profile_json.h"
#include "runtime/live_session.h"
#include "runtime/null_output.h"
#include "runtime/render_pipeline.h"
#include "scene/trajectory.h"
#include "scene/validate.h"

namespace dpc::bench {
namespace {

/// The session's output: a real device, or NullOutput (a timer thread at the block rate).
struct Output {
  std::unique_ptr<NullOutput> null;
  std::unique_ptr<audio::AudioOutput> real;

  void start() { null ? null->start() : real->start(); }
  void stop() { null ? null->stop() : real->stop(); }
  audio::CallbackStats::Snapshot stats() const {
    return null ? null->stats().snapshot() : real->stats().snapshot();
  }
};

Output openOutput(const SceneDesc& scene, const LiveOptions& o, LiveSession& session) {
  Output out;
  if (o.device.empty()) {
    out.null = std::make_unique<NullOutput>(scene.audio.sampleRate, o.blockSize, 2,
                                            &LiveSession::renderCallback, &session);
  } else {
    audio::AudioOutput::Options ao;
    ao.device = o.device;
    ao.sampleRate = scene.audio.sampleRate;
    ao.channels = 2;
    ao.blockSize = o.blockSize;
    out.real = std::make_unique<audio::AudioOutput>(ao, &LiveSession::renderCallback, &session);
  }
  return out;
}

/// Walks the scene's listener along its trajectory, a pose every 5 ms, for `duration` s.
void walk(const SceneDesc& scene, double duration, LiveSession& session) {
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (t >= duration) break;
    session.setPose(listenerPositionAt(scene.listeners[0], t), 0.f, t);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

/// Render times of the blocks in `st` as percentages of the block period.
Json renderLoad(const audio::CallbackStats& st, double periodNs) {
  const auto snap = st.snapshot();
  return Json{{"blocks", snap.callbacks},
              {"median_pct", 100.0 * double(snap.quantileNs(0.5)) / periodNs},
              {"p999_pct", 100.0 * double(snap.quantileNs(0.999)) / periodNs},
              {"max_pct", 100.0 * double(snap.maxNs) / periodNs}};
}

Json report(const CommonOptions& c, const LiveOptions& o, const SceneDesc& scene,
            const PropagationSettings& s, const LiveSession& session) {
  const double periodNs = 1e9 * o.blockSize / scene.audio.sampleRate;
  const LiveSession::Status st = session.status();
  Json j;
  j["benchmark"] = "live";
  j["scene"] = c.scene;
  j["device"] = o.device.empty() ? "null (timer thread at the block rate)" : o.device;
  j["sample_rate"] = scene.audio.sampleRate;
  j["block_size"] = o.blockSize;
  j["block_period_ms"] = periodNs * 1e-6;
  j["rays_per_frame"] = s.raysPerFrame;
  // Adaptive rays (docs/live.md): what the controller traced to hold the frame rate.
  j["rays_per_frame_last"] = st.raysPerFrame;
  j["rays_per_frame_min"] = st.raysPerFrameMin;
  j["reduced_frames"] = st.reducedFrames;
  j["rays_per_frame_p5"] = st.raysPerFrameP5;
  j["rays_per_frame_median"] = st.raysPerFrameMedian;
  j["floor_frames"] = st.floorFrames;
  j["frame_rate_target"] = s.frameRate;
  j["threads"] = s.threads;
  j["duration_s"] = o.duration;
  j["frames"] = st.frames;
  j["frames_per_second"] = double(st.frames) / o.duration;
  j["irs_applied"] = st.irsApplied;
  const auto lat = session.latencyStats().snapshot();
  j["motion_to_sound_latency_ms"] = {{"samples", lat.callbacks},
                                     {"median", double(lat.quantileNs(0.5)) * 1e-6},
                                     {"p95", double(lat.quantileNs(0.95)) * 1e-6},
                                     {"max", double(lat.maxNs) * 1e-6}};
  j["frame_profile_ms"] = frameProfileJson(session.frameProfile());
  const HybridReport hybrid = session.hybridReport();
  j["late_bus_tolerance_db"] = o.lateBusToleranceDb;
  j["late_bus_irs"] = {{"synthesized", hybrid.counts.busesSynthesized},
                       {"kept", hybrid.counts.busesKept}};
  j["source_ir_tolerance_db"] = o.sourceIrToleranceDb;
  j["source_irs"] = {{"synthesized", session.sourceIrCounts().synthesized},
                     {"kept", session.sourceIrCounts().kept}};
  j["render_time_with_ir_swap"] = renderLoad(session.renderStatsWithSwap(), periodNs);
  j["render_time_without_ir_swap"] = renderLoad(session.renderStatsWithoutSwap(), periodNs);
  return j;
}

}  // namespace

int benchLive(const CommonOptions& c, const LiveOptions& o) {
  const auto shared = std::make_shared<SceneDesc>(loadScene(c.scene));
  SceneDesc& scene = *shared;
  checkField("audio.block_size", o.blockSize, commandLineOrigin());
  scene.audio.blockSize = o.blockSize;
  PropagationSettings s = settingsFor(scene, c);
  if (o.frameRate > 0.0) checkField("propagation.frame_rate", o.frameRate, commandLineOrigin());
  if (o.frameRate > 0.0) s.frameRate = float(o.frameRate);
  LiveSession::Options lo;
  lo.deviceChannels = 2;
  lo.measureFftPlans = true;  // as dpc-demo's live sessions (apps/demo/run_live.cpp)
  lo.lateBusToleranceDb = o.lateBusToleranceDb;
  lo.sourceIrToleranceDb = o.sourceIrToleranceDb;
  lo.keepImpulseResponses = false;  // no reader: a game's or plugin's session
  const auto dry = std::make_shared<const DrySignals>(loadDrySignals(scene));
  const auto constructing = std::chrono::steady_clock::now();
  LiveSession session(shared, s, dry, lo);
  const double constructionSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - constructing).count();
  session.setPose(listenerPositionAt(scene.listeners[0], 0.0), 0.f, 0.0);
  Output output = openOutput(scene, o, session);
  session.start();
  output.start();
  walk(scene, o.duration, session);
  output.stop();
  session.stop();
  Json j = report(c, o, scene, s, session);
  const auto cb = output.stats();
  j["callbacks"] = cb.callbacks;
  j["xruns"] = cb.xruns;
  j["nan_blocks"] = session.status().nanBlocks;
  // dpc-demo opens the device first, then builds the session: the device's time to first
  // sound is the construction plus the time from start to the first block with sound.
  const double heard = session.status().firstSoundSeconds;
  j["time_to_first_sound_s"] = {
      {"session_construction", constructionSeconds},
      {"start_to_first_sound", std::isnan(heard) ? Json(nullptr) : Json(heard)},
      {"device_open_to_first_sound",
       std::isnan(heard) ? Json(nullptr) : Json(constructionSeconds + heard)}};
  // The synthesisers completed after the first frame (LiveSession::Options::quickFirstIr).
  const double completion = session.status().synthesisCompletionSeconds;
  j["time_to_first_sound_s"]["synthesis_completion_after_first_frame"] =
      std::isnan(completion) ? Json(nullptr) : Json(completion);
  // Measured from wisdom, or measured after the first frame within the run.
  j["fft_plans_measured"] = session.fftPlansMeasured();
  j["note"] =
      "latency: pose published by the control thread -> first block rendered with an "
      "IR computed for that pose; render time: LiveSession::render per block, % of the "
      "block period";
  printReport(j);
  return 0;
}

}  // namespace dpc::bench
