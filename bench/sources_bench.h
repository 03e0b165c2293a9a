// `dpc-bench sources`: frame time, peak memory and per-source quality against the number of
// sound sources, for both tracing directions (PropagationSettings::tracing).
#pragma once

#include <string>
#include <vector>

#include "bench/bench_util.h"

namespace dpc::bench {

struct SourcesOptions {
  std::vector<int> counts = {1, 4, 16, 64, 256};  ///< source counts (first = the reference)
  std::vector<std::string> tracing = {"from_sources", "from_listeners"};
  int warmupFrames = 20;     ///< frames before timing; quality is read after them
  int qualitySources = 4;    ///< sources whose energy response is compared with a reference
  int referenceFrames = 24;  ///< path-tracing frames (4x rays) of each reference
  /// Tracing from the sources is measured up to this many sources (its cost grows linearly:
  /// 256 sources take 256 passes a frame).
  int maxFromSources = 64;
  /// audio.rendering of every configuration: auto, per_source or hybrid.
  std::string rendering = "auto";
  /// Source IRs (early parts in hybrid rendering) and late buses kept within this many dB
  /// (PropagationStage::reuseSourceIrs, reuseLateBuses), as a live session keeps them; 0:
  /// every IR every frame, as offline renders synthesise them.
  double keepToleranceDb = 0.0;
};

/// For each tracing direction and source count: the scene's sources, then more at fixed
/// quasi-random points of the room's bounding box (shrunk by 15 % per side), all static; one
/// listener (the scene's first, static). Each configuration runs in a child process (fork) so
/// that its peak resident memory (getrusage of the child) is its own. Reported per frame after
/// warmupFrames: wall time of the propagation pass (tracing + caches) and of IR synthesis for
/// every source, cache bytes, exact paths, and, for the first qualitySources sources, the
/// energy error (dB) and the relative RMS noise per 10 ms bin and band of the energy response
/// against a converged path-tracing reference (bench/noise_study.h). JSON on stdout, a line
/// per configuration on stderr. Main thread. Returns 0; throws on bad input.
int benchSources(const CommonOptions& c, const SourcesOptions& o);

/// The scene with `count` sources: its own first, then copies of its first source at fixed
/// quasi-random points (Halton bases 2, 3, 5) of the mesh's bounding box shrunk by 15 % per
/// side. Any thread.
SceneDesc withSourceCount(const SceneDesc& scene, int count);

}  // namespace dpc::bench
