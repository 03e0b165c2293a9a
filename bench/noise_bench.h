// `dpc-bench noise`: the diffuse path cache's noise against plain path tracing, both measured
// against a converged reference (bench/noise_study.h), and the equal-noise ray ratio.
#pragma once

#include <vector>

#include "bench/bench_util.h"

namespace dpc::bench {

struct NoiseOptions {
  double walkSpeed = 0.0;     ///< listener speed along the trajectory, m/s (0 = static)
  int referenceFrames = 256;  ///< path-tracing frames per reference
  int warmup = -1;            ///< frames before measuring; < 0: 2 tau at the frame rate
  std::vector<int> ptMultipliers = {1, 2, 4, 8, 16, 32};  ///< ray multipliers of path tracing
};

/// Measures the scene's first source (rays default 4096) over c.frames frames after the
/// warm-up and prints the JSON report on stdout, progress on stderr. Main thread. Returns 0;
/// throws on bad input.
int benchNoise(const CommonOptions& c, const NoiseOptions& o);

}  // namespace dpc::bench
