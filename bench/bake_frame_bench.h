// `dpc-bench bake-frame`: what baked playback saves at run time. For each tracing direction and
// source count, the frame of a PropagationStage whose static sources are all played from a
// bake (runtime/baked_playback.h: not traced, FrameInputs::skippedPairs) against the same
// stage with every source live (no bake): the propagation pass (traceWorld: tracing, caches,
// direct sound, exact paths, the bake's interpolation) and IR synthesis (prepare), rays and
// segments per frame. The bake is synthetic (probes on a 1 m grid at the listener's height,
// a flat late response): its values do not change the cost. JSON on stdout, a line per
// configuration on stderr. Main thread; allocates.
#pragma once

#include <string>
#include <vector>

#include "bench/bench_util.h"

namespace dpc::bench {

struct BakeFrameOptions {
  std::vector<int> counts = {1, 4, 16};  ///< static source counts
  std::vector<std::string> tracing = {"from_sources", "from_listeners"};
  int warmupFrames = 5;  ///< untimed frames first (cache growth, page faults)
};

int benchBakeFrame(const CommonOptions& c, const BakeFrameOptions& o);

}  // namespace dpc::bench
