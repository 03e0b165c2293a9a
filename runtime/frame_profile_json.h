// The frame profile (runtime/frame_profile.h) as JSON, one definition for dpc-demo's --stats
// file and dpc-bench live: per stage {frames, mean, median, p95, max} in milliseconds, and
// "pairs_cpu_s": the pairs' parts in CPU seconds over the run. Any thread; allocates.
#pragma once

#include <nlohmann/json.hpp>

#include "runtime/frame_profile.h"

namespace dpc {

nlohmann::ordered_json frameProfileJson(const FrameProfile::Snapshot& profile);

}  // namespace dpc
