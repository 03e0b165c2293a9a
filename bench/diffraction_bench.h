// `dpc-bench diffraction`: edge diffraction's load-time and per-pair cost.
#pragma once

#include "bench/bench_util.h"

namespace dpc::bench {

/// Edge diffraction cost (docs/validation.md): load-time edge finding, then per source-listener
/// pair and frame the direct sound plus EdgeDiffraction::apply (one thread), at c.frames
/// listener positions spread over the scene's listener's trajectory (its last keyframe's time,
/// or 20 s). JSON report on stdout, a summary line on stderr. Main thread. Returns 0; throws
/// on bad input.
int benchDiffraction(const CommonOptions& c);

}  // namespace dpc::bench
