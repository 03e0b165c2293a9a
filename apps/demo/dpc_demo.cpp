// dpc-demo: render a scene through the diffuse path cache, live through an audio device
// (run_live.h) or offline to WAV files (run_offline.h).
#include <cstdio>
#include <exception>

#include "apps/demo/audio_devices.h"
#include "apps/demo/flags.h"
#include "apps/demo/list_materials.h"
#include "apps/demo/run_live.h"
#include "apps/demo/run_offline.h"
#include "common/input_error.h"
#include "common/program_main.h"
#include "runtime/live_session.h"

namespace dpc::demo {
namespace {

/// Refuses options that belong to the other kind of run than the one asked for.
void checkRunKind(const Flags& fl) {
  if (!fl.offline.empty() && !fl.stats.empty())
    throw InputError("command line", "--stats", "is for live runs (offline prints its summary)");
  // An offline render would ignore them and exit 0 without the recording asked for.
  if (!fl.offline.empty() && !fl.record.empty())
    throw InputError("command line", "--record", "is for live runs (--offline writes the render)");
  if (!fl.offline.empty() && fl.interactive)
    throw InputError("command line", "--interactive", "is for live runs");
  if (fl.latencyTargetMs) {
    if (!fl.offline.empty())
      throw InputError("command line", "--latency-target-ms", "is for live runs");
    if (!(*fl.latencyTargetMs >= 1.0 && *fl.latencyTargetMs <= 10000.0))
      throw InputError("command line", "--latency-target-ms", "must be in [1, 10000] ms");
  }
  if (fl.irSwapSpreadMs) {
    if (!fl.offline.empty())
      throw InputError("command line", "--ir-swap-spread-ms", "is for live runs");
    const double maxMs = LiveSession::kMaxIrSwapSpreadSeconds * 1e3;
    if (!(*fl.irSwapSpreadMs >= 0.0 && *fl.irSwapSpreadMs <= maxMs))
      throw InputError("command line", "--ir-swap-spread-ms",
                       "must be in [0, " + std::to_string(int(maxMs)) + "] ms");
  }
  if (fl.offline.empty() && !fl.erOut.empty())
    throw InputError("command line", "--er-out", "needs --offline (offline renders only)");
  if (fl.offline.empty() && !fl.irOut.empty())
    throw InputError("command line", "--ir-out", "needs --offline (offline renders only)");
}

/// Runs what the flags ask for; returns the exit status.
int run(const Flags& fl) {
  if (fl.listDevices) return listDevices();
  if (fl.listMaterials) return listMaterials();
  if (fl.scene.empty()) {
    std::fprintf(stderr, "dpc-demo: a scene file is required (--help for usage)\n");
    return 1;
  }
  checkRunKind(fl);
  if (fl.offline.empty()) return runLive(fl);
  return runOffline(fl);
}

}  // namespace
}  // namespace dpc::demo

int main(int argc, char** argv) {
  dpc::demo::Flags fl;
  if (const auto status = dpc::demo::parseFlags(argc, argv, fl)) return *status;
  return dpc::runReportingErrors("dpc-demo", [&] { return dpc::demo::run(fl); });
}
