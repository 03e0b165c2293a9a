// `dpc-bench wave`: the wave band's cost (wave/, docs/wave.md).
#pragma once

#include <vector>

#include "bench/bench_util.h"

namespace dpc::bench {

struct WaveBenchOptions {
  std::vector<double> volumes{50.0, 200.0, 800.0};  ///< box volumes, m^3 (proportions 1.6:1.3:1)
  std::vector<double> frequencies{250.0, 500.0};    ///< wave.max_frequency, Hz
  double seconds = 0.25;                            ///< simulated seconds per run
};

/// Per box volume and maximum frequency: grid nodes, state bytes, steps, wall time of the grid
/// and of the simulation, and from them seconds per simulated second and cubic metre, bytes per
/// cubic metre and node updates per second; then a model of the scaling over MPI ranks (slabs
/// exchanging one plane per neighbour and step), stated as a prediction. JSON on stdout, a
/// summary on stderr. Main thread (TBB workers inside). Returns 0.
int benchWave(const WaveBenchOptions& o);

}  // namespace dpc::bench
