// `dpc-bench load`: scene load time against triangle count.
#pragma once

#include <vector>

#include "bench/bench_util.h"

namespace dpc::bench {

struct LoadOptions {
  /// Terrain sizes (testing/terrain.h): 2 cells^2 triangles each; 708 gives 1,002,528.
  std::vector<int> cells = {25, 50, 100, 200, 400, 708};
  int panels = 16;  ///< panels standing on the terrain (4 triangles each)
  /// Solid crates on it (12 triangles, 6 narrow faces each: the channels' neighbour search).
  int crates = 0;
};

/// For each size: writes the terrain as an OBJ mesh and a scene file into a temporary folder,
/// then times the load stages a renderer runs before its first frame: loadScene (OBJ parse,
/// mesh cleaning, validation), the patch geometry, the Embree BVH and the diffraction edge
/// finder. JSON report on stdout (one entry per size), a summary line per size on stderr.
/// Main thread. Returns 0; throws on a failure to write or load.
int benchLoad(const LoadOptions& o);

}  // namespace dpc::bench
