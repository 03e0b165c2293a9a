// `dpc-bench live`: motion-to-sound latency and the audio render load of a live session.
#pragma once

#include <string>

#include "bench/bench_util.h"
#include "runtime/live_session.h"

namespace dpc::bench {

struct LiveOptions {
  double duration = 20.0;  ///< seconds to run
  int blockSize = 128;     ///< audio block size, samples
  double frameRate = 0.0;  ///< propagation frames per second (<= 0: the scene's)
  std::string device;      ///< audio device ("" = a timer thread at the block rate, no device)
  /// LiveSession::Options::lateBusToleranceDb (hybrid rendering's late buses kept while their
  /// shape holds; 0: every bus synthesised every frame).
  double lateBusToleranceDb = LiveSession::Options{}.lateBusToleranceDb;
  /// LiveSession::Options::sourceIrToleranceDb (sources' own IRs kept while their inputs
  /// match; 0: every IR synthesised every frame).
  double sourceIrToleranceDb = LiveSession::Options{}.sourceIrToleranceDb;
};

/// Runs a LiveSession for o.duration seconds with the listener walking its trajectory and
/// prints the JSON report on stdout. Main thread (the session and the device run their own
/// threads). Returns 0; throws on bad input or a device that cannot be opened.
int benchLive(const CommonOptions& c, const LiveOptions& o);

}  // namespace dpc::bench
