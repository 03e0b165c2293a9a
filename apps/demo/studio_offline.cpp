#include "apps/demo/studio_offline.h"

#include <chrono>
#include <cstdio>
#include <thread>

#include "apps/demo/audio_devices.h"
#include "apps/demo/keyboard_motion.h"
#include "apps/demo/overrides.h"
#include "apps/demo/run_live.h"
#include "apps/demo/studio_host.h"
#include "common/stop_signals.h"

namespace dpc::demo {

void serveOfflineStudio(const LoadedRun& run, const Flags& fl) {
  const SceneDesc& scene = *run.scene;
  LiveSession::Options lo;
  lo.listener = selectedListener(scene, fl);
  lo.deviceChannels = deviceChannels(scene.audio);
  lo.bake = run.bake;
  lo.keepSurfaceEnergy = true;  // the heat map
  LiveSession session(run.scene, run.settings, run.dry, lo);
  KeyboardMotion motion(scene, session.playedListener());
  StudioHost studio(scene, fl);
  std::fprintf(stderr, "studio: offline clock, %.0f frames per second at most; Ctrl-C ends\n",
               double(scene.propagation.frameRate));
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / scene.propagation.frameRate));
  auto next = std::chrono::steady_clock::now();
  bool first = true;
  while (!stopSignal()) {
    studio.applyRequests(motion, session);
    // The offline clock: one frame period of scene time per frame (not the first).
    motion.advance(first ? 0.0 : 1.0 / scene.propagation.frameRate);
    first = false;
    publishPoses(scene, motion, session);
    session.step();
    studio.publish(session, motion, studio::StudioFigures{});
    next += period;
    const auto now = std::chrono::steady_clock::now();
    if (next < now) next = now;  // a slow frame: no catching up in a burst
    std::this_thread::sleep_until(next);
  }
}

}  // namespace dpc::demo
