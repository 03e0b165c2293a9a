// dpc-bake's command line (CLI11) and its checks. Control thread; allocates; parseOptions
// throws InputError("command line", flag, ...) for a bad value and CLI::ParseError for
// malformed syntax (the caller prints CLI11's message).
#pragma once

#include <string>
#include <vector>

#include "bake/probe_bake.h"
#include "bake/probe_grid.h"

namespace dpc::bake {

/// Most rays per source and frame, and most frames per probe, a bake accepts (each bounds the
/// time of one probe; docs/bake.md gives the cost per ray).
inline constexpr int kMaxBakeRays = 1 << 20;
inline constexpr int kMaxBakeFrames = 4096;

struct Options {
  std::string scene;   ///< SCENE.json (fresh bake; optional with --resume)
  std::string out;     ///< --out BAKE.h5 (fresh bake)
  std::string resume;  ///< --resume BAKE.h5
  std::string map;     ///< --map MAP.csv: parameter map after the bake
  std::string probes;  ///< --probes LIST: probe positions instead of a grid
  std::vector<double> box;  ///< --box x0 y0 z0 x1 y1 z1 (metres), empty for the horizontal grid
  GridRequest grid;
  bool spacingGiven = false;
  BakeSettings settings;
  bool raysGiven = false;
  bool quiet = false;  ///< no progress line
  bool json = false;   ///< a JSON summary on stdout at the end (dpc-bench bake reads it)
  /// --force: bake beyond the limits of apps/bake/estimate.h and the free space of the disk
  bool force = false;
};

/// Parses argv; returns false (after printing help) when the program should exit 0 at once.
bool parseOptions(int argc, char** argv, Options& o);

}  // namespace dpc::bake
