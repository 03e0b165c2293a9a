// dpc-demo: render a scene through the diffuse path cache, live through an audio device
// (run_live.h) or offline to WAV files (run_offline.h).
#include <cstdio>
#include <exception>
#include <optional>
#include <string>

#include "apps/demo/audio_devices.h"
#include "apps/demo/flags.h"
#include "apps/demo/list_materials.h"
#include "apps/demo/run_live.h"
#include "apps/demo/run_offline.h"
#include "common/input_error.h"
#include "common/program_main.h"
#include "runtime/live_session.h"
#include "scene/limits.h"

namespace dpc::demo {
namespace {

/// A live-only number: refused in an offline run and outside [lo, hi] (in `unit`).
void checkLiveNumber(const Flags& fl, const std::optional<double>& v, const char* flag, double lo,
                     double hi, const char* unit) {
  if (!v) return;
  if (!fl.offline.empty()) throw InputError("command line", flag, "is for live runs");
  if (!(*v >= lo && *v <= hi))
    throw InputError("command line", flag,
                     "must be in [" + valueText(lo) + ", " + valueText(hi) + "] " + unit);
}

/// Refuses options that belong to the other kind of run than the one asked for.
void checkRunKind(const Flags& fl) {
  if (!fl.offline.empty() && !fl.stats.empty())
    throw InputError("command line", "--stats", "is for live runs (offline prints its summary)");
  // An offline render would ignore them and exit 0 without the recording asked for.
  if (!fl.offline.empty() && !fl.record.empty())
    throw InputError("command line", "--record", "is for live runs (--offline writes the render)");
  if (!fl.offline.empty() && fl.interactive)
    throw InputError("command line", "--interactive", "is for live runs");
  checkLiveNumber(fl, fl.latencyTargetMs, "--latency-target-ms", 1.0, 10000.0, "ms");
  checkLiveNumber(fl, fl.irSwapSpreadMs, "--ir-swap-spread-ms", 0.0,
                  LiveSession::kMaxIrSwapSpreadSeconds * 1e3, "ms");
  checkLiveNumber(fl, fl.reconnectSeconds, "--reconnect", 0.0, kMaxReconnectSeconds, "s");
  if (fl.port && !fl.studio) throw InputError("command line", "--port", "needs --studio");
  if (fl.port && !(*fl.port >= 0 && *fl.port <= 65535))
    throw InputError("command line", "--port", "must be in [0, 65535] (0: any free port)");
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
