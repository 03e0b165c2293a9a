// dpc-demo --stats FILE.json: what a live run measured, for scripts and CI.
#pragma once

#include <string>

#include "audio/audio_output.h"
#include "runtime/live_session.h"

namespace dpc::demo {

/// Writes --stats FILE.json (docs/live.md "Statistics file"): device, callback scheduling,
/// callbacks, xruns, late and rejected callbacks, callback and render loads (callback
/// durations as a percentage of the block period), rays per frame, IRs applied and dropped,
/// motion-to-sound latency (pose published -> first block rendered with the IR traced for it)
/// and the limiter. cb: the device's statistics over the run; swap / noSwap: the session's
/// render times with and without an IR swap; reconnections: devices reopened after a failure
/// (--reconnect; the device fields are the last one's). Main thread, after the session stopped.
/// Allocates; the file is replaced only once complete; throws std::runtime_error if it cannot
/// be written.
void writeLiveStats(const std::string& path, const std::string& scenePath,
                    const audio::AudioOutput& output,
                    const audio::AudioOutput::Scheduling& scheduling, const LiveSession& session,
                    const LiveSession::Status& st, const audio::CallbackStats::Snapshot& cb,
                    const audio::CallbackStats::Snapshot& swap,
                    const audio::CallbackStats::Snapshot& noSwap, int reconnections);

}  // namespace dpc::demo
