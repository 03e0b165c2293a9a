// One run of dpc-bake on one rank: plan the bake (a fresh grid, or what an incomplete file
// still needs), bake this rank's share of the probes, and on rank 0 commit every probe to the
// file as it arrives, then mark the file complete and write the map. Each rank's main thread;
// allocates. Returns the exit status: 0 when the bake is complete, 1 after one line on stderr
// (rank 0) for bad input, 128 + n after one line for a stop signal n (SIGINT, SIGTERM, SIGHUP;
// common/stop_signals.h: the current probe is committed, and the file is left incomplete for
// --resume; before the file is opened, none is created).
#pragma once

#include "apps/mpi/cluster.h"
#include "apps/bake/options.h"

namespace dpc::bake {

int runBake(const Options& options, Cluster& cluster);

}  // namespace dpc::bake
