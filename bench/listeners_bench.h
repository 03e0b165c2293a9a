// `dpc-bench listeners`: frame time for several listeners traced in one pass.
#pragma once

#include <vector>

#include "bench/bench_util.h"

namespace dpc::bench {

struct ListenersOptions {
  std::vector<int> counts = {1, 2, 4, 8};  ///< listener counts (first = the reference)
  int warmupFrames = 5;  ///< frames run before timing (cache fill, first-touch page faults)
};

/// Frame time for several listeners traced in one pass (docs/dynamic.md, "Several
/// listeners"): one PropagationStage per listener count, stepped frame by frame in turn (so
/// that load from other processes falls on all counts alike); wall-clock frame time and process
/// CPU time of the pass (tracing + one cache per source-listener pair) and CPU time of
/// preparing every listener's IR set. JSON report on stdout, one line per count on stderr.
/// Main thread. Returns 0; throws on bad input.
int benchListeners(const CommonOptions& c, const ListenersOptions& o);

}  // namespace dpc::bench
