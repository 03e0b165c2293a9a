// `dpc-bench dynamic`: door step response per estimator and tau, moving-object frame time and
// noise of a walking source, on built-in scenes (testing/test_scenes.h).
#pragma once

#include <string>

namespace dpc::bench {

struct DynamicOptions {
  int rays = 2048;                                   ///< rays per frame
  int frames = 20;                                   ///< frames per object-count measurement
  std::string parts = "step,objects,moving_source";  ///< the parts to run, comma-separated
};

/// Runs the parts named in o.parts (docs/dynamic.md) and prints the JSON report on stdout,
/// one line per case on stderr. Main thread. Returns 0.
int benchDynamic(const DynamicOptions& o);

}  // namespace dpc::bench
