// `dpc-bench propagation`: frame time and segments per second of the full frame against bare
// Embree loops, IR synthesis time (mono and binaural).
#pragma once

#include "bench/bench_util.h"

namespace dpc::bench {

/// `dpc-bench propagation`'s own options.
struct PropagationOptions {
  bool noRoulette = false;  ///< every ray to max order
  bool recordSurfaces = false;  ///< Simulation::recordSurfaces (dpc studio's heat map)
  Tracing tracing = Tracing::kFromSources;
  /// Frames run before timing: the first frames grow the cache (allocation, first-touch page
  /// faults) and would charge that one-off cost to the steady-state segments per second.
  int warmupFrames = 5;
};

/// Times c.frames frames of the scene's first source (rays default 4096, max order 200) after
/// o.warmupFrames untimed ones and prints the JSON report on stdout, progress on stderr. Main
/// thread (tracing uses c.threads). Returns 0; throws on bad input.
int benchPropagation(const CommonOptions& c, const PropagationOptions& o);

}  // namespace dpc::bench
