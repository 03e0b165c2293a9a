// `dpc-bench budget`: the diffuse path cache's memory budget against rays per frame.
#pragma once

#include <vector>

#include "bench/bench_util.h"

namespace dpc::bench {

/// Memory budget sweep (docs/estimators.md): for each rays-per-frame value, the DPC at the
/// budget and an unbounded one (the largest budget allowed, pages committed only as used) see the same rays; the
/// JSON gives entries, bytes, merged entries, the coarse store's share and the budget's bias
/// (total energy and strength G of the last frame, budgeted vs unbounded). c.scene
/// "room-4x3x2.5" is a built-in shoebox. Main thread. Returns 0; throws on bad input.
int benchBudget(const CommonOptions& c, const std::vector<int>& raysList);

}  // namespace dpc::bench
