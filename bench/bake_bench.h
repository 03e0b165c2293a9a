// `dpc-bench bake`: probes per second of dpc-bake (apps/bake) against the probe count, as one
// process on 1 and 2 threads and as `mpirun -np 2` (1 thread per rank), and the throughput
// those measurements predict for more ranks. Runs the dpc-bake program (the bench layer does
// not link the apps), reading its --json summary. JSON report on stdout, a line per run on
// stderr. Main thread; starts processes; throws std::runtime_error when a run fails.
#pragma once

#include <string>
#include <vector>

namespace dpc::bench {

struct BakeBenchOptions {
  std::string scene;
  std::vector<double> spacings = {2.0, 1.0, 0.5};  ///< grid spacings, metres (probe counts)
  int rays = 1000;                                 ///< rays per source and frame
  int frames = 8;                                  ///< frames per probe
  std::string bake;    ///< the dpc-bake program (default: ../apps/dpc-bake beside dpc-bench)
  std::string mpirun = "mpirun";  ///< empty or missing: the MPI runs are skipped
  /// The level planned on paper: probes, nodes, cores per node, and the link into the writer
  /// (bytes/s) that bounds a gather.
  double planProbes = 1e5, planNodes = 64, planCoresPerNode = 32, planLinkBytesPerSecond = 1e9;
};

int benchBake(const BakeBenchOptions& o);

}  // namespace dpc::bench
