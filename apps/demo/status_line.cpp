// Formatting of the live run's status line, scheduling line and summary line.
#include "apps/demo/status_line.h"

#include <cmath>
#include <cstdio>

namespace dpc::demo {

void printScheduling(const audio::AudioOutput::Scheduling& scheduling, bool tty) {
  std::fprintf(stderr, "%saudio callback: %s priority %d%s\n", tty ? "\r" : "", scheduling.policy,
               scheduling.priority,
               scheduling.realTime ? " (real-time)"
                                   : ": real-time priority not granted (JACK: start jackd "
                                     "with -R; ALSA: needs rtprio, e.g. ulimit -r or "
                                     "/etc/security/limits.d), xruns are likely under load");
}

void printStatusLine(const LiveSession::Status& st, const audio::AudioOutput& output,
                     const audio::CallbackStats::Snapshot& callbacks, double sceneSeconds,
                     bool tty) {
  std::fprintf(stderr,
               "%sframe %5.1f ms | rays %5d/%d | %6.0fk rays/s | cache %7zu %5.1f/%.0f MB "
               "merged %llu "
               "(%4.1f%%) | IR age %5.1f ms | "
               "latency %5.1f/%5.1f ms | load %4.1f%% | xruns %llu | limiter %llu (-%.1f dB) | "
               "t %.1f s%s",
               tty ? "\r" : "", st.frameMs, st.raysPerFrame, st.raysPerFrameScene,
               st.raysPerSecond / 1e3, st.cacheEntries, st.cacheBytes / 1e6,
               st.cacheBudgetBytes / 1e6, (unsigned long long)st.cacheMergedEntries,
               100.0 * st.cacheMergedEnergyFraction, st.irAgeMs, st.latencyMedianMs,
               st.latencyP95Ms, output.loadPercent(callbacks.quantileNs(0.5)),
               (unsigned long long)callbacks.xruns, (unsigned long long)st.limitedFrames,
               st.limiterMaxReductionDb, sceneSeconds, tty ? "   " : "\n");
}

void printLiveSummary(const LiveSession::Status& st, const audio::AudioOutput& output,
                      const audio::CallbackStats::Snapshot& callbacks,
                      const audio::CallbackStats::Snapshot& swap,
                      const audio::CallbackStats::Snapshot& noSwap) {
  const auto& cb = callbacks;
  std::printf(
      "live: frames=%llu irs_applied=%llu irs_dropped=%llu blocks=%llu callbacks=%llu "
      "xruns=%llu nan_blocks=%llu late_callbacks=%llu rejected_callbacks=%llu "
      "latency_median_ms=%.1f "
      "latency_p95_ms=%.1f callback_load_median_pct=%.1f callback_load_max_pct=%.1f "
      "render_swap_p999_pct=%.1f render_noswap_p999_pct=%.1f limited_frames=%llu "
      "over_ceiling_frames=%llu limiter_max_reduction_db=%.2f rays_per_frame=%d "
      "rays_per_frame_min=%d rays_per_frame_scene=%d reduced_frames=%llu baked_responses=%llu "
      "bake_fallbacks=%llu max_order_energy_fraction=%.3g\n",
      (unsigned long long)st.frames, (unsigned long long)st.irsApplied,
      (unsigned long long)st.irsDropped, (unsigned long long)st.blocks,
      (unsigned long long)cb.callbacks, (unsigned long long)cb.xruns,
      (unsigned long long)st.nanBlocks, (unsigned long long)st.lateCallbacks,
      (unsigned long long)st.rejectedCallbacks, st.latencyMedianMs, st.latencyP95Ms,
      output.loadPercent(cb.quantileNs(0.5)), output.loadPercent(cb.maxNs),
      output.loadPercent(swap.quantileNs(0.999)), output.loadPercent(noSwap.quantileNs(0.999)),
      (unsigned long long)st.limitedFrames, (unsigned long long)st.overCeilingFrames,
      st.limiterMaxReductionDb, st.raysPerFrame, st.raysPerFrameMin, st.raysPerFrameScene,
      (unsigned long long)st.reducedFrames, (unsigned long long)st.bakedResponses,
      (unsigned long long)st.bakeFallbacks, st.maxOrderEnergyFraction);
}

bool warnMaxOrder(const std::string& scene, int maxOrder, double share, bool tty) {
  if (!(share > kMaxOrderWarnFraction)) return false;
  std::fprintf(stderr, "%swarning: %s: %s\n", tty ? "\r" : "", scene.c_str(),
               maxOrderWarning(maxOrder, share).c_str());
  return true;
}

void printHybrid(const HybridReport& h) {
  if (!h.on) return;
  std::printf(
      "hybrid rendering: early part %.0f ms per source, %d late buses (%d in use, largest "
      "cluster radius %.0f deg)  cluster switches %llu  joined for want of a bus %llu  direct "
      "sounds rendered late %llu  late bus IRs synthesised %llu, kept %llu\n",
      1e3 * h.earlySeconds, h.buses, h.counts.occupiedBuses, h.counts.maxAngularRadiusDegrees,
      (unsigned long long)h.counts.switches, (unsigned long long)h.counts.forcedJoins,
      (unsigned long long)h.counts.lateDirect, (unsigned long long)h.counts.busesSynthesized,
      (unsigned long long)h.counts.busesKept);
}

}  // namespace dpc::demo
