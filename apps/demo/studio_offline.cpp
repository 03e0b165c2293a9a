#include "apps/demo/studio_offline.h"

#include <chrono>
#include <cstdio>
#include <memory>
#include <thread>
#include <vector>

#include "apps/demo/audio_devices.h"
#include "apps/demo/keyboard_motion.h"
#include "apps/demo/overrides.h"
#include "apps/demo/run_live.h"
#include "apps/demo/studio_host.h"
#include "apps/studio/studio_audio.h"
#include "audio/rt_check.h"
#include "common/stop_signals.h"

namespace dpc::demo {
namespace {

/// The stepped session's sound for the page (Web Audio): after each frame, one frame period
/// of it rendered by the session's own audio-thread call, in its blocks, into the board's ring.
class PageSound {
 public:
  PageSound(LiveSession& session, int channels, double frameRate,
            std::shared_ptr<studio::StudioAudio> ring)
      : session_(session),
        framePeriodSamples_(double(session.sampleRate()) / frameRate),
        ring_(std::move(ring)),
        buffers_(size_t(channels), std::vector<float>(size_t(session.blockSize()))) {
    for (auto& b : buffers_) pointers_.push_back(b.data());
  }

  void afterFrame() {
    due_ += framePeriodSamples_;
    const int block = session_.blockSize();
    for (; due_ >= double(block); due_ -= double(block)) {
      {
        // This thread plays the audio thread for the render call only (the offline clock has
        // none); the ring's lock is taken back in its own role.
        audio::rt::ScopedThreadRole role(audio::rt::ThreadRole::kAudio);
        session_.render(nullptr, pointers_.data(), block);
      }
      ring_->append(pointers_.data(), size_t(block));
    }
  }

 private:
  LiveSession& session_;
  double framePeriodSamples_;
  double due_ = 0.0;  ///< samples of scene time not rendered yet
  std::shared_ptr<studio::StudioAudio> ring_;
  std::vector<std::vector<float>> buffers_;
  std::vector<float*> pointers_;
};

}  // namespace

void serveOfflineStudio(const LoadedRun& run, const Flags& fl) {
  const SceneDesc& scene = *run.scene;
  LiveSession::Options lo;
  lo.listener = selectedListener(scene, fl);
  lo.deviceChannels = deviceChannels(scene.audio);
  lo.bake = run.bake;
  lo.keepSurfaceEnergy = true;  // the heat map
  // The offline clock has no deadline: every IR every frame, as the offline renderer makes
  // them (the page plays what --offline writes).
  lo.lateBusToleranceDb = 0.0;
  lo.sourceIrToleranceDb = 0.0;
  LiveSession session(run.scene, run.settings, run.dry, lo);
  KeyboardMotion motion(scene, session.playedListener());
  std::shared_ptr<studio::StudioAudio> ring;
  std::unique_ptr<PageSound> sound;
  if (studio::StudioAudio::playable(lo.deviceChannels)) {
    ring = std::make_shared<studio::StudioAudio>(session.sampleRate(), lo.deviceChannels);
    sound = std::make_unique<PageSound>(session, lo.deviceChannels,
                                        double(scene.propagation.frameRate), ring);
  }
  StudioHost studio(scene, fl, ring);
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
    if (sound) sound->afterFrame();
    studio.publish(session, motion, studio::StudioFigures{});
    next += period;
    const auto now = std::chrono::steady_clock::now();
    if (next < now) next = now;  // a slow frame: no catching up in a burst
    std::this_thread::sleep_until(next);
  }
}

}  // namespace dpc::demo
