// Drives a LiveSession the way a device would, for the real-time tests: an audio-role thread
// renders blocks of 128 frames (paced at ~4x real time so frames keep arriving at 60/s), at
// least `blocks` of them and on until `minIrsApplied` IR sets were swapped in (a slow or loaded
// machine traces fewer frames per block; at most 50 x `blocks`), while the calling thread walks
// the listener along the shoebox trajectory.
// `onAudioThread` runs on the audio thread around the blocks: begin() before the first, end()
// after the last (e.g. to count heap calls there). `control` adds to what the calling thread
// does: configure(options) before the session is built, step(scene, session) on every pass of
// its loop (as dpc-demo's control loop serves dpc studio), finish() before the session stops.
#pragma once

#include <fftw3.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/fftw_util.h"
#include "common/fftw_wisdom.h"
#include "runtime/live_session.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"

namespace dpc::test {

struct LiveRun {
  LiveSession::Status status;
  bool finite = true;
  size_t recordedFrames = 0;
  HybridReport hybrid;  ///< LiveSession::hybridReport() after stop()
  /// LiveSession::fftPlansMeasured() after construction and after stop().
  bool plansMeasuredAtStart = false, plansMeasured = false;
};

/// The calling thread does only the listener's walk.
struct NoControl {
  void configure(LiveSession::Options&) {}
  void step(const SceneDesc&, LiveSession&) {}
  void finish() {}
};

/// tracingThreads: the propagation's TBB arena (0 = all cores). With head-tracked binaural
/// output the listener also turns (half a radian per second), so the audio thread turns the
/// sound field between IR swaps. plansMeasuredLater: measured FFT plans with no FFTW wisdom in
/// the process or on file (LiveSession::Options::measureFftPlans), so that the session's
/// planner thread swaps its plans in while the audio thread renders; the run lasts until it
/// has.
template <typename AudioThreadObserver, typename Control = NoControl>
LiveRun driveLiveSession(int blocks, uint64_t minIrsApplied, AudioThreadObserver& onAudioThread,
                         int tracingThreads = 0, Rendering rendering = Rendering::kAuto,
                         OutputFormat output = OutputFormat::kMono,
                         bool plansMeasuredLater = false, Control&& control = Control{}) {
  LiveRun run;
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  scene.audio.blockSize = 128;
  scene.audio.rendering = rendering;
  if (output != OutputFormat::kMono) scene.audio.output = output;
  const float turn = output == OutputFormat::kAmbisonicBinaural ? 0.5f : 0.f;  // rad/s
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 256;
  ps.maxOrder = 30;
  ps.irLength = 0.5f;
  ps.frameRate = 60.f;  // many swaps in a short test
  ps.threads = tracingThreads;
  const DrySignals dry = loadDrySignals(scene);
  LiveSession::Options opt;
  opt.recordSeconds = 10.0;  // exercise the recorder ring too
  if (plansMeasuredLater) {
    setenv("DPC_FFTW_WISDOM", "", 1);  // no wisdom file
    std::lock_guard lock(fftwPlannerMutex());
    importFftwWisdomOnce();
    fftwf_forget_wisdom();
    opt.measureFftPlans = true;
  }
  control.configure(opt);
  LiveSession session(test::shared(scene), ps, test::shared(dry), opt);
  run.plansMeasuredAtStart = session.fftPlansMeasured();
  session.setPose(listenerPositionAt(scene.listeners[0], 0.0), 0.f, 0.0);
  session.start();

  std::vector<float> left(128), right(128);
  float* out[2] = {left.data(), right.data()};
  std::atomic<bool> done{false};
  std::thread audio([&] {
    onAudioThread.begin();
    for (int b = 0; !done.load(std::memory_order_relaxed) && b < 50 * blocks; ++b) {
      session.render(nullptr, out, 128);
      for (float x : left) run.finite = run.finite && std::isfinite(x);
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    onAudioThread.end();
  });
  const auto start = std::chrono::steady_clock::now();
  while (!done.load(std::memory_order_relaxed)) {
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    session.setPose(listenerPositionAt(scene.listeners[0], t), turn * float(t), t);
    control.step(scene, session);
    const LiveSession::Status st = session.status();
    const bool plans = !plansMeasuredLater || session.fftPlansMeasured();
    done.store((st.blocks >= uint64_t(blocks) && st.irsApplied >= minIrsApplied && plans) ||
                   st.blocks >= 50 * uint64_t(blocks),
               std::memory_order_relaxed);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  audio.join();
  control.finish();
  session.stop();
  run.status = session.status();
  run.plansMeasured = session.fftPlansMeasured();
  run.hybrid = session.hybridReport();
  run.recordedFrames = session.takeRecording().frames();
  return run;
}

}  // namespace dpc::test
