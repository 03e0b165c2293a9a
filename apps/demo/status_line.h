// What a live dpc-demo run prints while it plays and when it ends.
#pragma once

#include "audio/audio_output.h"
#include "runtime/live_session.h"

namespace dpc::demo {

/// The callback thread's scheduling, one line on stderr ("audio callback: SCHED_FIFO priority
/// 80 (real-time)", or why real-time priority matters). tty: stderr is a terminal (the line
/// then starts with a carriage return over the status line). Main thread.
void printScheduling(const audio::AudioOutput::Scheduling& scheduling, bool tty);

/// The once-a-second status line on stderr: frame time, rays, cache, IR age, latency, callback
/// load over `callbacks` (the window since the run started), xruns, limiter and scene time.
/// On a terminal it is redrawn in place; otherwise one line each. Main thread.
void printStatusLine(const LiveSession::Status& st, const audio::AudioOutput& output,
                     const audio::CallbackStats::Snapshot& callbacks, double sceneSeconds,
                     bool tty);

/// The end-of-run summary on stdout: one line "live: key=value ..." for scripts (docs/live.md).
/// callbacks: the device's statistics over the run; swap / noSwap: the session's render times
/// of blocks with and without an IR swap. Main thread.
void printLiveSummary(const LiveSession::Status& st, const audio::AudioOutput& output,
                      const audio::CallbackStats::Snapshot& callbacks,
                      const audio::CallbackStats::Snapshot& swap,
                      const audio::CallbackStats::Snapshot& noSwap);

/// Warns on stderr when the rays max_order ended still carried more than kMaxOrderWarnFraction
/// of the emitted energy (`share`, largest band: SessionStatus::maxOrderEnergyFraction); returns
/// whether it did. `scene`: the scene file's path. tty: as printScheduling. Main thread.
bool warnMaxOrder(const std::string& scene, int maxOrder, double share, bool tty);

/// Hybrid rendering's summary line on stdout (early part, late buses in use, largest cluster,
/// cluster switches, sources joined for want of a bus, direct sounds rendered late); nothing
/// when it was off. Shared by live and offline runs. Main thread.
void printHybrid(const HybridReport& report);

}  // namespace dpc::demo
