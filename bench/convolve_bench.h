// `dpc-bench convolve`: dpc's convolvers against zita-convolver (the yardstick, linked by the
// benchmark only) on the same IRs and input, CPU time of all threads.
#pragma once

#include <string>
#include <vector>

#include "audio/nonuniform_convolver.h"

namespace dpc::bench {

struct ConvolveOptions {
  std::vector<int> blocks = {64, 128, 256, 512};  ///< block sizes, samples
  double seconds = 3.0;                           ///< audio rendered per measurement
  double swapIntervalMs = 66.0;                   ///< IR swap period of the swapping runs
  int sampleRate = 48000;
  bool uniform = true;  ///< also time the uniformly partitioned convolver (no swaps)
  std::vector<std::string> cases;  ///< case ids to run (empty: all)
  /// K: partitions each level of dpc's layout reaches into the next (NonUniformLayout).
  int overlap = audio::NonUniformLayout::kDefaultOverlap;
};

/// Prints the JSON report on stdout; returns the process exit code.
int benchConvolve(const ConvolveOptions& options);

}  // namespace dpc::bench
