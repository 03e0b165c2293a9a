// What a bake will cost, estimated before it starts (probes, file size, time), and the limits
// over which dpc-bake refuses it unless --force: a mistyped --spacing (0.01 for 1) must not
// start a 50 GB, five-day bake without a word. docs/bake.md, "Before a bake starts".
// Time: one frame of the bake's rays traced at the scene's first listener, measured on this
// machine (ProbeBaker::timeFrame), times the frames per probe and the probes, over the
// processes. Size: the file is allocated whole when it is created (bake/bake_file.h), so its
// size is known exactly but for HDF5's metadata (at most kMetadataBytes).
// Control thread; no allocation beyond strings; errors as InputError.
#pragma once

#include <array>
#include <cstddef>
#include <string>

#include "bake/bake_layout.h"
#include "bake/probe_bake.h"

namespace dpc::bake {

/// Above any of these a bake is refused unless --force (documented in docs/bake.md).
inline constexpr size_t kMaxProbesUnforced = 100'000;
inline constexpr double kMaxBytesUnforced = 16e9;
inline constexpr double kMaxSecondsUnforced = 24.0 * 3600.0;
/// Bound on the HDF5 metadata of a bake file (superblock, object headers, attributes), bytes.
inline constexpr double kMetadataBytes = 64e3;

struct BakeEstimate {
  size_t probes = 0;        ///< probes to bake
  bool upperBound = false;  ///< probes counts grid candidates, not yet placed
  double bytes = 0.0;       ///< the bake file's size, bytes
  double seconds = 0.0;     ///< wall time of the probes to bake
  double frameSeconds = 0;  ///< one frame, measured
  int processes = 1;
};

/// The wave band's share of a bake (the scene's wave.enabled; apps/bake/bake_wave.h): one
/// simulation per source and octave band to the crossover, each of `steps` time steps over a
/// grid of `nodes` nodes (its bounding box, padding included).
struct WaveEstimate {
  size_t simulations = 0;
  std::array<int, 3> count{};  ///< nodes per axis
  size_t nodes = 0;
  size_t steps = 0;
};
/// "2 simulations of a 146 x 44 x 102 grid for 4356 steps (5.7e9 node updates)".
std::string describe(const WaveEstimate& e);

/// The file size of a bake of `probes` probes of `shape` (every dataset, allocated whole).
double bakeFileBytes(size_t probes, const ProbeShape& shape);
/// The bytes of a bake's wave band (docs/bake-format.md): 0 when `wave` is not enabled.
double waveBandBytes(size_t probes, size_t sources, const WaveLayout& wave);
BakeEstimate estimateBake(size_t probes, size_t fileProbes, const ProbeShape& shape,
                          const BakeSettings& settings, double frameSeconds, int processes);
/// "70 probes, a 6.5 MB file, about 14 s on 1 process (0.025 s per frame measured)".
std::string describe(const BakeEstimate& e);
/// Throws InputError("command line", flag, ...) with the estimate and the limits when any
/// limit is exceeded and `force` is not set.
void checkLimits(const BakeEstimate& e, bool force, const std::string& flag);
/// Throws InputError(path, "", ...) when the file system that will hold `path` has less free
/// space than `bytes` and `force` is not set.
void checkFreeSpace(const std::string& path, double bytes, bool force);

}  // namespace dpc::bake
