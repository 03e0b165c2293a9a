// The JSON statistics file of a live dpc-demo run.
#include "apps/demo/live_stats.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "common/output_file.h"
#include "runtime/frame_profile_json.h"

namespace dpc::demo {

namespace {

using Json = nlohmann::ordered_json;
using Snapshot = audio::CallbackStats::Snapshot;

/// Durations of `s` as percentages of the block period.
Json loadJson(const audio::AudioOutput& output, const Snapshot& s) {
  return Json{{"mean", output.loadPercent(s.meanNs())},
              {"median", output.loadPercent(s.quantileNs(0.5))},
              {"p99", output.loadPercent(s.quantileNs(0.99))},
              {"p99_9", output.loadPercent(s.quantileNs(0.999))},
              {"max", output.loadPercent(s.maxNs)}};
}

/// The first late callbacks: when each started (s after the session's start) and its ms.
Json lateCallbacksJson(const SessionStatus& st) {
  Json list = Json::array();
  const uint64_t kept = std::min<uint64_t>(st.lateCallbacks, SessionStatus::kLateCallbacksKept);
  for (size_t i = 0; i < kept; ++i)
    list.push_back(Json{{"at_s", st.lateCallbackAtSeconds[i]}, {"ms", st.lateCallbackMs[i]}});
  return list;
}

/// Motion-to-sound latencies, milliseconds.
Json latencyJson(const Snapshot& lat) {
  auto ms = [](uint64_t ns) { return double(ns) * 1e-6; };
  return Json{{"count", lat.callbacks},
              {"median", ms(lat.quantileNs(0.5))},
              {"p95", ms(lat.quantileNs(0.95))},
              {"p99", ms(lat.quantileNs(0.99))},
              {"max", ms(lat.maxNs)}};
}

Json schedulingJson(const audio::AudioOutput::Scheduling& scheduling) {
  return Json{{"known", scheduling.known},
              {"policy", scheduling.policy},
              {"priority", scheduling.priority},
              {"real_time", scheduling.realTime}};
}

/// Hybrid rendering of the played listener, or null when every source was rendered whole.
Json hybridJson(const HybridReport& h) {
  if (!h.on) return Json(nullptr);
  return Json{{"early_ms", 1e3 * h.earlySeconds},
              {"late_buses", h.buses},
              {"occupied_buses", h.counts.occupiedBuses},
              {"largest_cluster_radius_deg", h.counts.maxAngularRadiusDegrees},
              {"frames", h.counts.frames},
              {"cluster_switches", h.counts.switches},
              {"forced_joins", h.counts.forcedJoins},
              {"late_bus_irs_synthesized", h.counts.busesSynthesized},
              {"late_bus_irs_kept", h.counts.busesKept},
              {"late_direct_sounds", h.counts.lateDirect},
              {"late_exact_arrivals", h.counts.lateArrivals}};
}

}  // namespace

void writeLiveStats(const std::string& path, const std::string& scenePath,
                    const audio::AudioOutput& output,
                    const audio::AudioOutput::Scheduling& scheduling, const LiveSession& session,
                    const LiveSession::Status& st, const Snapshot& cb, const Snapshot& swap,
                    const Snapshot& noSwap, int reconnections) {
  const Json j = {
      {"scene", scenePath},
      {"sample_rate_hz", output.sampleRate()},
      {"block_frames", output.blockSize()},  // the device's period
      {"engine_block_frames", session.blockSize()},
      {"channels", output.channels()},
      {"device", output.device().spec()},
      {"reconnections", reconnections},
      {"callback_scheduling", schedulingJson(scheduling)},
      {"callbacks", cb.callbacks},
      {"xruns", cb.xruns},
      {"late_callbacks", st.lateCallbacks},
      {"late_callbacks_first", lateCallbacksJson(st)},
      {"rejected_callbacks", st.rejectedCallbacks},
      {"nan_blocks", st.nanBlocks},
      // The long partitions are computed inside the callback, spread over the blocks of their
      // period (docs/live.md): there are no convolution worker threads that could miss one.
      {"worker_deadline_misses", 0},
      {"worker_threads", 0},
      {"callback_load_percent", loadJson(output, cb)},
      {"render_load_percent",
       {{"with_ir_swap", loadJson(output, swap)}, {"without_ir_swap", loadJson(output, noSwap)}}},
      {"propagation_frames", st.frames},
      {"tracing_threads", session.settings().threads},
      {"ir_swap_spread_blocks", session.irSwapSpreadBlocks()},
      {"rays_per_frame",
       {{"last", st.raysPerFrame},
        {"min", st.raysPerFrameMin},
        {"p5", st.raysPerFrameP5},
        {"median", st.raysPerFrameMedian},
        {"floor", st.raysPerFrameFloor},
        {"floor_frames", st.floorFrames},
        {"scene", st.raysPerFrameScene},
        {"reduced_frames", st.reducedFrames}}},
      {"cache",
       {{"entries", st.cacheEntries},
        {"bytes", st.cacheBytes},
        {"budget_bytes", st.cacheBudgetBytes},
        {"pool_used_bytes", st.cachePoolUsedBytes},
        {"pairs", st.cachePairs},
        {"pair_bytes_min", st.cachePairBytesMin},
        {"pair_bytes_max", st.cachePairBytesMax},
        {"entries_merged", st.cacheMergedEntries}}},
      {"irs_applied", st.irsApplied},
      {"fft_plan_failures", st.fftPlanFailures},
      {"irs_dropped", st.irsDropped},
      {"irs_lost", st.irsLost},
      {"stale_partitions", st.stalePartitions},
      {"dropped_energy_fraction", st.droppedEnergyFraction},
      {"max_order_energy_fraction", st.maxOrderEnergyFraction},
      {"max_order_energy_fraction_peak", st.maxOrderEnergyFractionPeak},
      {"diffraction_chains_left_out", st.chainsLeftOut},
      {"hybrid_rendering", hybridJson(session.hybridReport())},
      {"source_irs",
       {{"synthesized", session.sourceIrCounts().synthesized},
        {"kept", session.sourceIrCounts().kept}}},
      {"motion_to_sound_latency_ms", latencyJson(session.latencyStats().snapshot())},
      {"frame_profile_ms", frameProfileJson(session.frameProfile())},
      // Session start -> first block holding a sample other than 0 (null: never).
      {"time_to_first_sound_s",
       std::isnan(st.firstSoundSeconds) ? Json(nullptr) : Json(st.firstSoundSeconds)},
      // Head-tracked binaural: pose published -> first block turned by it.
      {"head_turn_latency_ms",
       session.headTracked() ? latencyJson(session.headLatencyStats().snapshot()) : Json(nullptr)},
      {"limiter",
       {{"limited_frames", st.limitedFrames},
        {"over_ceiling_frames", st.overCeilingFrames},
        {"max_reduction_db", st.limiterMaxReductionDb}}}};
  const std::string text = j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
  TempOutputFile file(path);
  file.writeAll(text.data(), text.size());
  file.commit();
}

}  // namespace dpc::demo
