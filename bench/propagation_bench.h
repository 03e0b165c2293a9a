// `dpc-bench propagation`: frame time and segments per second of the full frame against bare
// Embree loops, IR synthesis time (mono and binaural).
#pragma once

#include "bench/bench_util.h"

namespace dpc::bench {

/// Times c.frames frames of the scene's first source (rays default 4096, max order 200;
/// noRoulette: every ray to max order) and prints the JSON report on stdout, progress on
/// stderr. Main thread (tracing uses c.threads). Returns 0; throws on bad input.
int benchPropagation(const CommonOptions& c, bool noRoulette, Tracing tracing);

}  // namespace dpc::bench
