// dpc-demo: render a scene through the diffuse path cache, live through an audio device
// (run_live.h) or offline to WAV files (run_offline.h).
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <tuple>

#include "apps/demo/audio_devices.h"
#include "apps/demo/flags.h"
#include "apps/demo/list_materials.h"
#include "apps/demo/preflight.h"
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
  if (!fl.offline.empty() && !fl.device.empty())
    throw InputError("command line", "--device", "is for live runs (--offline writes a file)");
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

/// The flag that set a scene field, when the user gave it: a check of the settings together
/// (cache_tau x frame_rate, the memory a cache needs) or of the file a flag names (--hrtf)
/// blames the flag, not the scene file's field the user never wrote. Null otherwise.
const char* flagThatSet(const Flags& fl, const std::string& field) {
  const std::tuple<const char*, const char*, bool> kSet[] = {
      {"propagation.cache_tau", "--tau", fl.tau.has_value()},
      {"propagation.cache_memory_mb", "--cache-memory-mb", fl.cacheMb.has_value()},
      {"propagation.cache_pool_mb", "--cache-pool-mb", fl.cachePoolMb.has_value()},
      {"propagation.rays_per_frame", "--rays", fl.rays.has_value()},
      {"propagation.max_order", "--max-order", fl.maxOrder.has_value()},
      {"propagation.dpc_weighting", "--dpc-weighting", !fl.weighting.empty()},
      {"audio.hrtf", "--hrtf", !fl.hrtf.empty()},
      {"audio.block_size", "--block-size", fl.blockSize.has_value()},
      {"audio.ambisonic_order", "--ambisonic-order", fl.ambisonicOrder.has_value()},
      {"audio.late_buses", "--late-buses", fl.lateBuses.has_value()},
      {"audio.cluster_angle", "--cluster-angle", fl.clusterAngle.has_value()}};
  for (const auto& [key, flag, given] : kSet)
    if (given && field == key) return flag;
  return nullptr;
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
  try {
    return fl.offline.empty() ? runLive(fl) : runOffline(fl);
  } catch (const SceneFileError&) {
    throw;
  } catch (const InputError& e) {
    const char* flag = e.file() == fl.scene ? flagThatSet(fl, e.field()) : nullptr;
    if (!flag) throw;
    throw InputError("command line", flag, e.problem());
  }
}

}  // namespace
}  // namespace dpc::demo

int main(int argc, char** argv) {
  dpc::demo::Flags fl;
  if (const auto status = dpc::demo::parseFlags(argc, argv, fl)) return *status;
  return dpc::runReportingErrors("dpc-demo", [&] { return dpc::demo::run(fl); });
}
