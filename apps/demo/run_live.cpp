// dpc-demo's live run: checks, the session and its device, the control loop, the summary.
#include "apps/demo/run_live.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "apps/demo/audio_devices.h"
#include "apps/demo/keyboard_motion.h"
#include "apps/demo/live_stats.h"
#include "apps/demo/overrides.h"
#include "apps/demo/preflight.h"
#include "apps/demo/status_line.h"
#include "apps/demo/studio_host.h"
#include "apps/demo/terminal.h"
#include "audio/callback_watchdog.h"
#include "audio/wav_io.h"
#include "common/input_error.h"
#include "common/stop_signals.h"
#include "runtime/callback_adapter.h"
#include "runtime/propagation_stage.h"
#include "scene/limits.h"
#include "scene/orientation.h"
#include "scene/trajectory.h"
#include "scene/validate.h"

namespace dpc::demo {
namespace {

using Clock = std::chrono::steady_clock;

/// Seconds a live run plays when --duration is not given (until 'q' or a signal).
constexpr double kUnboundedSeconds = 1e9;

/// Longest wait for the audio device to stop, seconds: a device whose server is gone never
/// answers, and the session must end within 2 s of the failure.
constexpr double kStopTimeoutSeconds = 1.0;

/// What the control loop learnt that the summary and --stats report.
struct Playback {
  /// The callback thread's scheduling, read once a callback has run.
  audio::AudioOutput::Scheduling scheduling;
  /// The device's callback statistics when playback started.
  audio::CallbackStats::Snapshot atStart;
  /// Why the device failed during playback ("" if it did not).
  std::string failure;
  /// The callbacks of the devices that failed before the one playing (--reconnect).
  audio::CallbackStats::Snapshot earlier;
  /// Devices reopened after a failure (--reconnect).
  int reconnections = 0;
  /// The failed device was already stopped (or abandoned) by a reconnection attempt.
  bool deviceStopped = false;
  /// The max_order warning was printed (once a run).
  bool maxOrderWarned = false;
};

/// The callbacks played so far: the failed devices' and the current one's since it started.
audio::CallbackStats::Snapshot playedCallbacks(const Playback& pb,
                                               const audio::AudioOutput& output) {
  return pb.earlier.plus(output.stats().snapshot().since(pb.atStart));
}

/// Applies the overrides and checks everything that can be checked before playing.
PropagationSettings prepareLive(SceneDesc& scene, const Flags& fl) {
  applyAudioOverrides(scene, fl);
  printSceneWarnings(scene);
  if (fl.listener.empty() && scene.listeners.size() > 1)
    std::fprintf(stderr, "note: playing listener \"%s\" of %zu (choose with --listener NAME)\n",
                 scene.listeners[0].name.c_str(), scene.listeners.size());
  PropagationSettings settings = applyOverrides(scene, fl);
  // Live: leave one core to the audio thread unless --threads says otherwise; runLive gives
  // tracing every core when the device's callback is real-time (tracingThreads).
  if (!fl.threads) settings.threads = std::max(1, int(std::thread::hardware_concurrency()) - 1);
  checkDuration(fl);
  checkOutputs(scene, fl);
  requireSignal(scene);
  checkSetup(scene, settings, 0.0, true);
  return settings;
}

LiveSession::Options sessionOptions(const SceneDesc& scene, const Flags& fl,
                                    double durationSeconds) {
  LiveSession::Options lo;
  lo.listener = selectedListener(scene, fl);
  lo.deviceChannels = deviceChannels(scene.audio);
  lo.measureFftPlans = true;  // faster callbacks; measured after the first sound if not in wisdom
  lo.keepImpulseResponses = fl.studio;  // only the studio page reads them
  lo.keepSurfaceEnergy = fl.studio;     // its heat map
  if (fl.latencyTargetMs) lo.latencyTargetSeconds = *fl.latencyTargetMs * 1e-3;
  // --record streams to its file (memory does not grow with the session).
  if (!fl.record.empty()) {
    lo.recordSeconds = durationSeconds;  // > 0 enables the recorder; no memory is reserved
    lo.recordPath = fl.record;
  }
  return lo;
}

/// Applies the keys waiting on the terminal; true if one of them asked to quit.
bool readKeys(RawTerminal& terminal, KeyboardMotion& motion, LiveSession& session) {
  bool quit = false;
  for (int k = terminal.key(); k; k = terminal.key()) {
    switch (motion.key(k)) {
      case KeyboardMotion::Action::kQuit:
        quit = true;
        break;
      case KeyboardMotion::Action::kNextListener:
        session.selectListener(motion.playedIndex());
        std::fprintf(stderr, "\nlistener \"%s\"\n", motion.played().name.c_str());
        break;
      case KeyboardMotion::Action::kNone:
        break;
    }
  }
  return quit;
}

/// The once-a-second report: the callback's scheduling as soon as it is known, the max_order
/// warning the first time the largest cut of any frame so far exceeds its bound, then the
/// status line.
void reportStatus(const SceneDesc& scene, const LiveSession& session,
                  const audio::AudioOutput& output, Playback& pb, double sceneSeconds, bool tty) {
  if (!pb.scheduling.known) {
    pb.scheduling = output.callbackScheduling();
    if (pb.scheduling.known) printScheduling(pb.scheduling, tty);
  }
  const LiveSession::Status st = session.status();
  if (!pb.maxOrderWarned)
    pb.maxOrderWarned =
        warnMaxOrder(scene.path, session.settings().maxOrder, st.maxOrderEnergyFractionPeak, tty);
  printStatusLine(st, output, playedCallbacks(pb, output), sceneSeconds, tty);
}

/// Stops the device (at most kStopTimeoutSeconds) and the session; says so if a device that
/// had not failed could not be stopped.
void stopPlayback(LiveSession& session, audio::AudioOutput& output, const Playback& pb) {
  const bool failed = !pb.failure.empty();
  if (!pb.deviceStopped && !output.stopWithin(kStopTimeoutSeconds) && !failed)
    std::fprintf(stderr, "note: the audio device did not stop within %.0f s; abandoned\n",
                 kStopTimeoutSeconds);
  session.stop();
}

/// Time between two attempts to reopen a failed device (--reconnect).
constexpr auto kReconnectInterval = std::chrono::milliseconds(500);

/// Opens and starts the device again every kReconnectInterval until it plays, `deadline`
/// passes or a stop signal arrives. Returns the started device or null, `why` the last
/// attempt's reason.
std::unique_ptr<audio::AudioOutput> reopen(const SceneDesc& scene, const Flags& fl,
                                           std::unique_ptr<LiveSession>& session,
                                           Clock::time_point deadline, std::string& why) {
  while (Clock::now() + kReconnectInterval <= deadline && !stopSignal()) {
    std::this_thread::sleep_for(kReconnectInterval);
    std::unique_ptr<audio::AudioOutput> next = tryOpenOutput(scene, fl, &session, why);
    if (!next) continue;
    try {
      next->start();
      return next;
    } catch (const std::exception& e) {
      why = e.what();
    }
  }
  return nullptr;
}

/// --reconnect: after a device failure, stops and closes the failed device and reopens the
/// same one (its spec, e.g. "JACK:system"; reopen());
/// the session traces on meanwhile (IR sets that find no callback are dropped and counted).
/// Returns whether playback resumed; if not, pb.failure says why. A device that does not stop
/// within kStopTimeoutSeconds is not replaced: its callback might still come back.
bool reconnect(const SceneDesc& scene, const Flags& fl, std::unique_ptr<LiveSession>& session,
               std::unique_ptr<audio::AudioOutput>& output, Playback& pb) {
  const double window = fl.reconnectSeconds.value_or(0.0);
  if (window <= 0.0) return false;
  std::fprintf(stderr, "\ndpc-demo: audio device '%s': %s; reopening it for up to %s s\n",
               output->device().spec().c_str(), pb.failure.c_str(), valueText(window).c_str());
  pb.deviceStopped = true;
  if (!output->stopWithin(kStopTimeoutSeconds)) {
    pb.failure += "; not reopened: the failed device did not stop";
    return false;
  }
  output->close();  // before a new client connects (AudioOutput::close)
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(window));
  // The same device, not whatever the default would be now (JACK gone: PortAudio's).
  Flags same = fl;
  same.device = output->device().spec();
  std::string why;
  std::unique_ptr<audio::AudioOutput> next = reopen(scene, same, session, deadline, why);
  if (!next) {
    pb.failure += "; not back within " + valueText(window) + " s" +
                  (why.empty() ? std::string() : " (last attempt: " + why + ")");
    return false;
  }
  pb.earlier = playedCallbacks(pb, *output);
  output = std::move(next);
  pb.atStart = output->stats().snapshot();
  pb.failure.clear();
  pb.deviceStopped = false;
  ++pb.reconnections;
  std::fprintf(stderr, "dpc-demo: reopened %s: playing again\n", output->device().spec().c_str());
  return true;
}

/// --studio: the page's requests before the poses are published, and a frame for the page
/// after (the device's callback load and xruns with it).
void studioRequests(StudioHost* studio, KeyboardMotion& motion, LiveSession& session) {
  if (studio) studio->applyRequests(motion, session);
}
void studioPublish(StudioHost* studio, const KeyboardMotion& motion, LiveSession& session,
                   const audio::AudioOutput& output, const Playback& pb) {
  if (!studio) return;
  studio::StudioFigures figures;
  figures.live = true;
  const audio::CallbackStats::Snapshot cb = playedCallbacks(pb, output);
  figures.loadPercent = output.loadPercent(cb.quantileNs(0.5));
  figures.xruns = cb.xruns;
  studio->publish(session, motion, figures);
}

/// --interactive: the terminal in raw mode, its keys said once; else null.
std::unique_ptr<RawTerminal> openTerminal(const Flags& fl) {
  if (!fl.interactive) return nullptr;
  auto terminal = std::make_unique<RawTerminal>();
  std::fprintf(stderr,
               "keys: arrows/WASD move, Q/E turn, space pauses the trajectory, l next "
               "listener, q quits\n");
  return terminal;
}

/// Starts the session and the device, moves the listener every 10 ms until the duration has
/// passed, 'q', a stop signal or a device failure (watchdog) that --reconnect did not mend,
/// then stops both.
Playback play(const SceneDesc& scene, const Flags& fl, double durationSeconds,
              std::unique_ptr<LiveSession>& sessionPtr,
              std::unique_ptr<audio::AudioOutput>& output) {
  LiveSession& session = *sessionPtr;
  KeyboardMotion motion(scene, session.playedListener());
  session.setPose(motion.position(), motion.yaw(), 0.0);
  Playback pb;
  const std::unique_ptr<RawTerminal> terminal = openTerminal(fl);
  const auto studio = fl.studio ? std::make_unique<StudioHost>(scene, fl) : nullptr;
  StudioHost* const page = studio.get();
  session.start();
  output->start();
  const auto start = Clock::now();
  auto last = start, lastStatus = start;
  pb.atStart = output->stats().snapshot();
  std::optional<audio::CallbackWatchdog> watchdog(std::in_place, *output);
  const bool tty = isatty(STDERR_FILENO);
  // A steady 10 ms tick (not 10 ms after each pass's work): the propagation thread aligns its
  // frames to the poses' rate (runtime/pose_sync.h), so a regular stream serves it best.
  auto tick = start;
  for (bool quit = false; !quit && !stopSignal();) {
    tick += std::chrono::milliseconds(10);
    if (tick < Clock::now()) tick = Clock::now();  // overran: no burst to catch up
    std::this_thread::sleep_until(tick);
    pb.failure = watchdog->check();
    if (!pb.failure.empty()) {
      if (!reconnect(scene, fl, sessionPtr, output, pb)) break;
      watchdog.emplace(*output);
    }
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    last = now;
    if (std::chrono::duration<double>(now - start).count() >= durationSeconds) break;
    if (terminal) quit = readKeys(*terminal, motion, session);
    studioRequests(page, motion, session);
    motion.advance(dt);
    publishPoses(scene, motion, session);
    studioPublish(page, motion, session, *output, pb);
    if (std::chrono::duration<double>(now - lastStatus).count() >= 1.0) {
      lastStatus = now;
      reportStatus(scene, session, *output, pb, motion.sceneTime(), tty);
    }
  }
  if (tty) std::fprintf(stderr, "\n");
  if (!pb.failure.empty())
    std::fprintf(stderr, "dpc-demo: error: audio device '%s': %s\n",
                 output->device().spec().c_str(), pb.failure.c_str());
  stopPlayback(session, *output, pb);
  return pb;
}

/// After playback: --record, the summary line, --stats.
void finishLive(const SceneDesc& scene, const Flags& fl, LiveSession& session,
                const audio::AudioOutput& output, const Playback& pb) {
  const auto st = session.status();
  const auto cb = playedCallbacks(pb, output);
  const auto swap = session.renderStatsWithSwap().snapshot();
  const auto noSwap = session.renderStatsWithoutSwap().snapshot();
  if (!fl.record.empty()) {
    const size_t frames = session.commitRecording();
    std::printf("wrote %s (%.2f s played, %llu samples dropped by the recorder)\n",
                fl.record.c_str(), double(frames) / scene.audio.sampleRate,
                (unsigned long long)st.recordDropped);
  }
  printLiveSummary(st, output, cb, swap, noSwap);
  if (st.fftPlanFailures)
    std::fprintf(stderr, "dpc-demo: warning: FFTW could not measure the convolvers' plans; the "
                         "session ran on estimated plans (the same sound, slower callbacks)\n");
  printHybrid(session.hybridReport());
  if (!fl.stats.empty()) {
    writeLiveStats(fl.stats, fl.scene, output, pb.scheduling, session, st, cb, swap, noSwap,
                   pb.reconnections);
    std::printf("wrote %s\n", fl.stats.c_str());
  }
}

/// "playing on JACK:system (...), 48000 Hz, period 128, engine block 128, ...", and which
/// output ports a JACK client left unconnected.
void printDevice(const SceneDesc& scene, const audio::AudioOutput& output) {
  std::fprintf(stderr,
               "playing on %s (%s), %.0f Hz, %d channels, period %d, engine block %d, output "
               "latency %.1f ms\n",
               output.device().spec().c_str(), output.device().hostApi.c_str(), output.sampleRate(),
               output.channels(), output.blockSize(), scene.audio.blockSize,
               output.outputLatency() * 1e3);
  const bool jack = output.device().hostApi.find("JACK") != std::string::npos;
  if (jack && scene.audio.output == OutputFormat::kAmbisonics && output.device().name == "system")
    std::fprintf(stderr,
                 "note: the %d AmbiX ports (ACN0...) are left unconnected: connect them "
                 "to a decoder (jack_connect, or --device jack:CLIENT)\n",
                 output.channels());
  else if (jack && output.device().maxOutputChannels < output.channels())
    std::fprintf(stderr, "note: %s has %d input ports; channels %d.. are left unconnected\n",
                 output.device().spec().c_str(), output.device().maxOutputChannels,
                 output.device().maxOutputChannels + 1);
}

}  // namespace

// Every listener is traced each frame: the played one where `motion` puts it, the others on
// their trajectories at the same scene time.
void publishPoses(const SceneDesc& scene, const KeyboardMotion& motion, LiveSession& session) {
  const double t = motion.sceneTime();
  for (size_t i = 0; i < scene.listeners.size(); ++i)
    if (i != motion.playedIndex()) {
      const Orientation o = listenerOrientationAt(scene.listeners[i], t);
      session.setListenerPose(i, listenerPositionAt(scene.listeners[i], t), o.yawRadians, t,
                              o.pitchRadians, o.rollRadians);
    }
  session.setPose(motion.position(), motion.yaw(), t, motion.pitch(), motion.roll());
}

/// Tracing threads for a live run: --threads if given; every core when the device promises
/// its callback real-time priority (a JACK server with -R: the callback preempts tracing, and
/// on the live market tracing on both of 2 cores cut latency p95 from 84-92 to 65-71 ms with
/// the callback load unchanged, docs/live.md); else all cores but one (an ordinary callback
/// thread competing with tracing on both of 2 cores was late in 245 blocks of 20 s, on one in
/// 24).
int tracingThreads(const Flags& fl, const PropagationSettings& settings,
                   const audio::AudioOutput& output) {
  if (fl.threads || !output.realTimeCallback()) return settings.threads;
  return std::max(1, int(std::thread::hardware_concurrency()));
}

/// The IR swap spread a live run uses unless --ir-swap-spread-ms says otherwise: none. The
/// swaps are cheap enough whole (the IR-swap blocks' p99 10-12 % of a 128-frame period on the
/// market and the dense hall, 64 sources each, where spreading was needed at 22-26 %), and a
/// spread adds its length to the motion-to-sound latency, which the ray controller pays in
/// rays (docs/live.md "Staggered swaps").
double irSwapSpreadSeconds(const Flags& fl) {
  return fl.irSwapSpreadMs ? *fl.irSwapSpreadMs * 1e-3 : 0.0;
}

int runLive(const Flags& fl) {
  const LoadedRun run = loadRun(fl, prepareLive);
  SceneDesc& scene = *run.scene;
  const double duration = fl.duration.value_or(kUnboundedSeconds);
  LiveSession::Options lo = sessionOptions(scene, fl, duration);
  lo.bake = run.bake;
  // The device first: a JACK server's period becomes the engine block (unless --block-size
  // says otherwise), so that every callback renders one block.
  std::unique_ptr<LiveSession> session;
  std::unique_ptr<audio::AudioOutput> output = openOutput(scene, fl, &session);
  if (!output) return kNoAudioDeviceStatus;
  if (!fl.blockSize) scene.audio.blockSize = engineBlockForHostPeriod(output->blockSize());
  PropagationSettings settings = run.settings;
  settings.threads = tracingThreads(fl, settings, *output);
  lo.irSwapSpreadSeconds = irSwapSpreadSeconds(fl);
  session = std::make_unique<LiveSession>(run.scene, settings, run.dry, lo);
  printDevice(scene, *output);
  catchStopSignals();
  const Playback pb = play(scene, fl, duration, session, output);
  finishLive(scene, fl, *session, *output, pb);
  // A device failure or a stop signal: what was played up to it is written, then the status.
  if (const int signal = stopSignal()) throw Interrupted(signal);
  return pb.failure.empty() ? 0 : 1;
}

}  // namespace dpc::demo
