// Scenes load in the background, on a thread the plugin owns, so that no host call waits for
// a scene to be built (instantiate, restore and the LV2 worker return at once) and no host
// thread ever runs dpc's engine construction or propagation (their TBB work then belongs to
// dpc's own threads alone, and TBB's workers are joined when the last engine is destroyed:
// api/scheduler_lease.h). One load runs at a time; a newer request supersedes an older one.
//
// In a host with a worker (a real-time host) the load also computes the scene's first
// propagation frame and starts its propagation thread if the plugin is active, then hands the
// scene to run() (Plugin::incoming), which swaps it in at the start of a block and tells the
// host on the notify port; the plugin is silent until its first scene arrives. In a host
// without a worker (lv2apply and other offline hosts, which run faster than real time),
// activate() and restore() wait for the load and compute the first frame (adoptNow), so that
// sound comes out of the first blocks (such a host also waits for the bundle's scene in
// instantiate, which returns NULL if it does not load).
#pragma once

#include <string>

#include "plugins/lv2/plugin.h"

namespace dpc::lv2 {

/// Non-audio thread: starts loading the scene at `path` and returns; waits only for an earlier
/// load still running (whose result is then dropped). A failed load is logged; the plugin
/// keeps the scene it plays (or its silence). Allocates.
void startLoad(Plugin* p, const std::string& path, bool isDefault);

/// Non-audio thread: waits until no load is running.
void waitForLoad(Plugin* p);

/// Host without a worker, not concurrent with run(): waits for the load, computes its first
/// frame for the control ports' pose, starts it if active and swaps it in (freeing the scene
/// it replaces). False if no loaded scene was waiting.
bool adoptNow(Plugin* p);

/// Non-audio thread: publishes the control ports' pose to `s` and computes one propagation
/// frame (the engine must be stopped). Logged on failure.
void firstFrame(Plugin* p, Scene& s);

/// Non-audio thread: frees the scene run() replaced, if any.
void collectOutgoing(Plugin* p);

}  // namespace dpc::lv2
