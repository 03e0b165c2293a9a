// dpc-demo --offline --studio: after the render, dpc studio on the offline clock.
#pragma once

#include "apps/demo/flags.h"
#include "apps/demo/preflight.h"

namespace dpc::demo {

/// Serves dpc studio (studio_host.h) over a LiveSession with no audio device whose frames
/// dpc-demo steps itself (LiveSession::step: the settings' rays, deterministic for a seed),
/// at most the scene's frame rate, scene time advancing one frame period per frame. The page
/// moves the listener and sources as in a live run. Runs until a stop signal (Ctrl-C). Main
/// thread. Throws InputError for a --port that cannot be bound.
void serveOfflineStudio(const LoadedRun& run, const Flags& fl);

}  // namespace dpc::demo
