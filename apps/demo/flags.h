// dpc-demo's command line: the options as parsed (CLI11), before any of them is checked
// against the scene (overrides.h, run_live.h, run_offline.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace dpc::demo {

/// Every dpc-demo option. An empty string or an empty optional means "not given", so that
/// any value the user gives, even one that looks like a default, is range-checked.
struct Flags {
  std::string scene, offline, irOut, erOut, estimator, tracing, weighting, device, record, stats,
      output, hrtf, listener, bake, rendering, binauralDecoder;
  bool listDevices = false, listMaterials = false, interactive = false, quiet = false,
       maxRe = false, studio = false;
  std::optional<int64_t> port;             ///< --studio's port (0: any free port)
  std::optional<int64_t> blockSize;        ///< samples per audio block (live)
  std::optional<double> duration;          ///< seconds to render or play
  std::optional<double> tau;               ///< cache response time, seconds
  std::optional<double> gainDb;            ///< fixed output gain, dB
  std::optional<double> cacheMb;           ///< DPC memory budget per source-listener pair, MB
  std::optional<double> cachePoolMb;       ///< DPC memory budget of the whole engine, MB
  std::optional<double> irSwapSpreadMs;    ///< live: LiveSession::Options::irSwapSpreadSeconds, ms
  std::optional<double> latencyTargetMs;   ///< live latency target, ms (default: LiveSession's)
  std::optional<double> reconnectSeconds;  ///< live: how long to try reopening a failed device
  std::optional<double> clusterAngle;      ///< hybrid rendering: a cluster's angular radius, deg
  std::optional<int64_t> lateBuses;        ///< hybrid rendering: late buses per listener
  std::optional<uint64_t> seed;
  std::optional<int64_t> rays, maxOrder, threads, ambisonicOrder;
};

/// Parses argv into `fl`. Returns the exit status when the program must stop here (0 after
/// --help; 1 after a parse error, printed as one line "dpc-demo: command line: ..." with the
/// closest option name when a flag looks mistyped), or nothing when parsing succeeded.
/// Main thread. Allocates.
std::optional<int> parseFlags(int argc, char** argv, Flags& fl);

}  // namespace dpc::demo
