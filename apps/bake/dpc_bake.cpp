// dpc-bake: bakes a scene's acoustics at a grid of probes into an HDF5 file (docs/bake.md,
// docs/bake-format.md), alone or as every rank of an Open MPI job.
//
//   dpc-bake SCENE.json --out BAKE.h5 --spacing M [--height M | --box X0 Y0 Z0 X1 Y1 Z1]
//            [--map MAP.csv]
//   dpc-bake --resume BAKE.h5 [SCENE.json] [--map MAP.csv]
//   mpirun -np N dpc-bake ...   (the same file, bit for bit)
//
// Control thread only. Bad input prints one line "FILE: FIELD: problem" on stderr (rank 0) and
// exits with status 1, leaving every file as it was.
#include "apps/bake/bake_run.h"
#include "common/program_main.h"

int main(int argc, char** argv) {
  return dpc::runReportingErrors("dpc-bake", [&] {
    dpc::Cluster cluster(argc, argv);
    dpc::bake::Options options;
    int status = 0;
    if (!dpc::together(cluster, "dpc-bake", [&] {
          if (!dpc::bake::parseOptions(argc, argv, options)) status = -1;
          return 0;
        }))
      return 1;
    if (status < 0) return 0;
    return dpc::bake::runBake(options, cluster);
  });
}
