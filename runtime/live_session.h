// LiveSession: the live pipeline. The same PropagationStage and AudioStage as offline
// rendering, on three threads (docs/design.md "Thread roles"):
//
//   control thread     setPose() (trajectory or keyboard), status(), start()/stop()
//   propagation thread assembles the frame's world state (HostPoses), traces all listeners
//                      in one pass, prepares the played listener's IrSet, pushes its pointer
//                      to the audio thread, recycles spent sets, stores the response snapshot
//   audio thread       render(): through the callback adapter, pops at most the newest IrSet
//                      per block (older ones go straight back), convolves and crossfades,
//                      mixes, limits, counts problems in relaxed atomics, feeds the recorder
//   planner thread     only with Options::measureFftPlans and no FFTW wisdom for the plans:
//                      measures the convolvers' plans once after the first frame
//
// It composes single-purpose parts: HostPoses (poses and world assembly), PropagationStage and
// AudioStage, two FixedRing<IrSet*> hand-over rings, CallbackAdapter (host block sizes),
// audio::Limiter, Recorder, ResponseSnapshot, SessionCounters and AdaptiveRays.
// render() never allocates, locks, logs, throws, waits or makes system calls (steady_clock is
// the vDSO); tests/rt checks it with an interposed allocator.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "audio/callback_stats.h"
#include "audio/limiter.h"
#include "common/fixed_ring.h"
#include "engine/simulation.h"
#include "runtime/adaptive_rays.h"
#include "runtime/callback_adapter.h"
#include "runtime/frame_profile.h"
#include "runtime/host_poses.h"
#include "runtime/recorder.h"
#include "runtime/render_pipeline.h"
#include "runtime/response_snapshot.h"
#include "runtime/session_stats.h"
#include "runtime/silence_watch.h"
#include "scene/trajectory.h"

namespace dpc {

class LiveSession {
 public:
  struct Options {
    int deviceChannels = 2;      ///< output channels the device renders (IR channels copied)
    double recordSeconds = 0.0;  ///< > 0: keep what was played (reserved for this many seconds)
    /// With recordSeconds > 0: stream what was played to this WAV file (Recorder) instead of
    /// keeping it in memory; commitRecording() renames it into place.
    std::string recordPath;
    int poolSize = 6;  ///< IR sets beyond two per slow partition level (>= 3; IrExchange)
    /// The listener played first (scene.listeners index; selectListener() changes it).
    size_t listener = 0;
    /// If set, static sources are played from this bake of the scene
    /// (PropagationStage::attachBake).
    std::shared_ptr<const BakedField> bake;
    /// The propagation thread adapts the rays per source of each frame to hold the frame
    /// rate (runtime/adaptive_rays.h, docs/live.md "Adaptive rays"): fewer rays when a frame
    /// takes longer than 1 / frame_rate, back up to the settings' rays when there is room.
    /// false: every frame traces the settings' rays, however long it takes.
    bool adaptiveRays = true;
    /// Motion-to-sound latency the adaptive rays aim under, seconds (pose published -> IR
    /// ready, plus one block for the audio thread to pick it up). Infinite: the frame period
    /// alone bounds the rays.
    double latencyTargetSeconds = 0.05;
    /// Measured FFTW plans for the convolvers (PropagationStage): faster callbacks, output
    /// that may differ from run to run in float rounding. Made from the wisdom of earlier runs
    /// when it holds them (common/fftw_wisdom.h); else the session starts with estimated plans
    /// and, once the first frame's IR is out, a thread of its own measures them (seconds) and
    /// swaps them in (ConvolverLayout::Planning::kMeasureLater; a stepped session keeps the
    /// estimated ones). Off by default (a plugin's instantiate must return quickly).
    bool measureFftPlans = false;
    /// Time over which each IR swap is spread across source groups, seconds, in
    /// [0, kMaxIrSwapSpreadSeconds], rounded to whole blocks (AudioStage::setIrSwapSpread;
    /// docs/live.md "Staggered swaps"): lighter blocks while IRs swap, for up to this much
    /// more motion-to-sound latency (counted in latencyStats()). 0: every source at once.
    double irSwapSpreadSeconds = 0.0;
    /// Hybrid rendering: a late bus keeps the IR it plays while its response's shape (each
    /// band's decay, apart from the level, which the sources' gains follow exactly) stays
    /// within this many dB of what that IR was made from (HybridSynthesis::reuseLateBuses); a
    /// frame then synthesises only the buses whose late field changed. 0: every bus every
    /// frame (as offline renders do). Default 0.5 dB: half ISO 3382-1's 1 dB just noticeable
    /// difference of G and C80, in every band and decay segment holding at least -30 dB of
    /// the late energy (LateShape).
    double lateBusToleranceDb = 0.5;
    /// A source's own IR (whole, or its early part in hybrid rendering) is kept while its
    /// inputs match what it was made from (PropagationStage::reuseSourceIrs, EarlySignature:
    /// the same exact arrivals at delays within a quarter sample, levels within this many
    /// dB, the energy per band and time segment within this many dB); a frame
    /// then synthesises and partitions only the IRs whose paths changed. 0: every IR every
    /// frame (as offline renders do). Default 0.5 dB, as lateBusToleranceDb.
    double sourceIrToleranceDb = 0.5;
    /// Whether copyResponses() offers each frame's whole IRs (Responses::ir). Building them
    /// (early parts plus their share of the late buses) is the largest part of the snapshot:
    /// 7 ms a frame for 64 sources of 2 s. false: Responses::ir holds no channels; the energy
    /// responses, direct sounds, paths and world are still copied. A session that no one asks
    /// for IRs (a game's output, a plugin, a benchmark) turns it off.
    bool keepImpulseResponses = true;
    /// Whether each frame's energy per surface is recorded and copied for readers
    /// (Responses::surfaces, Simulation::recordSurfaces: a hash-map insertion per hit).
    bool keepSurfaceEnergy = false;
    /// The mono IR synthesisers are built with what the first IR needs
    /// (IrSynthesizer::Build::kFirstIr) and completed right after the first frame (propagation
    /// thread, before the second frame) or before the first step(): the first sound comes
    /// sooner, its IR an unlevelled realisation of the same responses, and every later IR is
    /// the same bits as with false (docs/live.md "Time to first sound").
    bool quickFirstIr = true;
  };
  /// Upper bound of Options::irSwapSpreadSeconds: beyond it a swap outlasts a frame.
  static constexpr double kMaxIrSwapSpreadSeconds = 0.1;

  /// Control thread. Builds the stages (Embree scene, IR synthesisers, convolvers, rings) over
  /// the shared scene and dry signals (one per scene source). Allocates; throws on bad input
  /// (std::out_of_range for options.listener outside the scene's listeners). blockSize comes
  /// from scene->audio.blockSize.
  LiveSession(std::shared_ptr<const SceneDesc> scene, const PropagationSettings& settings,
              std::shared_ptr<const DrySignals> dry, const Options& options);
  ~LiveSession();

  /// Control thread: starts the propagation (and recorder) threads. The audio device, created
  /// by the caller, calls render() from its audio thread.
  void start();
  /// Control thread: stops and joins the threads. Idempotent.
  void stop();

  /// Any thread (one writer at a time): publishes a new pose (timestamped now) for the played
  /// listener (playedListener()). Yaw, pitch and roll as in dpc::Orientation (radians; yaw 0
  /// faces +x, positive turns left). Wait-free; no allocation.
  void setPose(const glm::vec3& position, float yawRadians, double sceneSeconds,
               float pitchRadians = 0.f, float rollRadians = 0.f);
  /// Any thread (one writer per listener at a time): publishes listener `index`'s pose
  /// (scene.listeners order), timestamped now, for the following propagation frames. Every
  /// listener is traced each frame in the same pass (its cache stays current whether it is
  /// played or not); until a pose is published a listener stands where its trajectory puts it
  /// at t = 0. sceneSeconds: the scene time the pose belongs to (sources and objects follow
  /// their trajectories at the played listener's time). Returns false (and changes nothing)
  /// for an index out of range. Wait-free (seqlock, runtime/pose_channel.h); no allocation.
  bool setListenerPose(size_t index, const glm::vec3& position, float yawRadians,
                       double sceneSeconds, float pitchRadians = 0.f, float rollRadians = 0.f);
  /// Any thread: plays listener `index` from the next propagation frame on (the audio thread
  /// crossfades to its IR like to any new IR). False for an index out of range. Wait-free.
  bool selectListener(size_t index) { return poses_.select(index); }
  /// The listener being played (scene.listeners order).
  size_t playedListener() const { return poses_.played(); }
  /// Listeners traced every frame: scene.listeners.size().
  size_t listenerCount() const { return poses_.listenerCount(); }
  /// Any thread (one writer per source at a time): places source `index` (scene order) at
  /// `position` (m) from the next propagation frame on, instead of its trajectory. Returns false
  /// (and changes nothing) for an index out of range. Wait-free; no allocation.
  bool setSourcePosition(size_t index, const glm::vec3& position) {
    return poses_.setSourcePosition(index, position);
  }
  /// Any thread: source (listener) `index` jumped; its pairs start over at the next frame
  /// (HostPoses::teleportSource). False for an index out of range. Wait-free; no allocation.
  bool teleportSource(size_t index) { return poses_.teleportSource(index); }
  bool teleportListener(size_t index) { return poses_.teleportListener(index); }
  /// Any thread (one writer per source at a time): source `index` turned by `rotation` (x, y,
  /// z, w; normalised here) instead of its keyframes; false for an index out of range or a
  /// zero-length rotation. Wait-free; no allocation.
  bool setSourceRotation(size_t index, const float rotation[4]) {
    return poses_.setSourceRotation(index, rotation);
  }
  /// Any thread (one writer per object at a time): object `index` at world = R(rotation) *
  /// local + position; rotation a unit quaternion (x, y, z, w), normalised here; false for an
  /// index out of range or a zero-length rotation. Wait-free; no allocation.
  bool setObjectPose(size_t index, const glm::vec3& position, const float rotation[4]) {
    return poses_.setObjectPose(index, position, rotation);
  }
  /// Control thread, while the propagation thread is not running (before start() or after
  /// stop()): runs one propagation frame now on the calling thread and hands its IR set to the
  /// audio side, as the propagation thread would. Lets a host render deterministically (same
  /// seed, same frames, same bits). Always traces the settings' rays (no adaptation: the
  /// result must not depend on the machine's speed). Returns false (nothing done) while
  /// running. Allocates while the cache's tables grow.
  bool step();
  /// As step(), but traced at the adaptive controller's current rays per source, after which
  /// the controller is told the frame took frameSeconds (seconds; instead of the wall clock)
  /// and picks the next frame's rays, as the propagation thread does after each frame. For
  /// hosts that run their own clock, and for tests of the controller that must not depend on
  /// the machine's load. Control thread, while not running (false otherwise).
  bool stepAdaptive(double frameSeconds);
  /// Control thread, while not running (false otherwise, nothing changed): plays the sources
  /// that stand at their baked positions from `bake` from the next frame on
  /// (PropagationStage::attachBake); replaces a bake attached before.
  bool attachBake(std::shared_ptr<const BakedField> bake);
  /// The scene the session plays (shared, read only).
  const SceneDesc& scene() const { return *scene_; }

  /// The newest frame's responses of the played listener for one source (ResponseSnapshot).
  using Responses = ResponseSnapshot::Responses;
  /// Any thread but the audio thread: calls f with the newest responses of `source` while
  /// holding the snapshot lock (the propagation thread skips its copy rather than wait for
  /// it, but waits once it skipped the frame before: ResponseSnapshot). Returns false, without
  /// calling f, before the first frame or for a bad index. Allocates nothing itself (f is called
  /// directly, not through a type-erased wrapper).
  template <class F>
  bool copyResponses(size_t source, F&& f) {
    return snapshot_.read(source, std::forward<F>(f));
  }

  /// IR channels (1 mono, 2 stereo/binaural, (order + 1)^2 AmbiX and head-tracked binaural).
  int irChannels() const { return propagation_->numOutputs(); }
  /// Channels rendered (renderedChannels(): 2 for head-tracked binaural, else irChannels()).
  int outputChannels() const { return int(stageOut_.size()); }

  /// Audio thread: renders `frames` frames (any count from 1 to kMaxCallbackFrames, varying
  /// from call to call) into outputs[0..deviceChannels). The engine works in fixed blocks of
  /// blockSize() frames; the callback adapter (runtime/callback_adapter.h) between the host's
  /// calls and those blocks adds a constant latency of adapterLatencyFrames() = blockSize()
  /// frames for every call pattern: output sample t (counted from the first call) is engine
  /// output sample t - blockSize() (zeros before). inputs: nullptr renders the scene's own dry
  /// signals; otherwise inputs[s][0..frames) is the host's dry input for source s (one mono
  /// channel per scene source, same order as scene.sources), delayed by the same latency.
  /// Calls with frames < 1 or > kMaxCallbackFrames render nothing and are counted
  /// (Status::rejectedCallbacks). The calling thread becomes the audio thread
  /// (audio/rt_check.h). Wait-free; no allocation, locks, logging, exceptions or system calls.
  void render(const float* const* inputs, float* const* outputs, int frames) noexcept;
  /// render(nullptr, outputs, frames): the scene's own dry signals.
  void render(float* const* outputs, int frames) noexcept { render(nullptr, outputs, frames); }
  /// Adapter with the audio::RenderCallback signature (user = LiveSession*; nullptr inputs).
  static void renderCallback(void* user, float* const* out, int frames) noexcept;

  /// Largest host callback render() accepts, frames.
  static constexpr int kMaxCallbackFrames = CallbackAdapter::kMaxCallbackFrames;
  /// Latency added by the callback-size adapter, frames (constant: one engine block).
  int adapterLatencyFrames() const { return adapter_.latencyFrames(); }
  /// Dry inputs render() expects when the host provides them (the scene's source count).
  int sourceCount() const { return adapter_.sourceCount(); }
  /// Rigid objects of the scene (setObjectPose() indices).
  int objectCount() const { return int(scene_->objects.size()); }

  int blockSize() const { return blockSize_; }
  /// The propagation settings the session was built with (threads: the tracing threads asked
  /// for, 0 = every core): the one copy, the simulation's. Any thread.
  const PropagationSettings& settings() const { return propagation_->simulation().settings(); }
  /// Blocks each IR swap is spread over (Options::irSwapSpreadSeconds in blocks, >= 1). Any
  /// thread.
  int irSwapSpreadBlocks() const;
  int sampleRate() const { return sampleRate_; }

  using Status = SessionStatus;
  /// Control thread (one reader): the counters, the latency quantiles, the limiter's and the
  /// recorder's counts.
  Status status() const;
  /// Hybrid rendering's report for the played listener (all zero, `on` false, when the scene
  /// renders every source whole). Control thread, while the propagation thread is stopped
  /// (before start() or after stop()): the counts are the propagation thread's. Allocates
  /// nothing.
  HybridReport hybridReport() const;
  /// The played listener's source IRs synthesised and kept (Options::sourceIrToleranceDb),
  /// cumulative. Threads as hybridReport().
  KeptIrs::Counts sourceIrCounts() const;

  /// Durations of render() per block, split by whether an IR swap (crossfade) happened.
  const audio::CallbackStats& renderStatsWithSwap() const { return swapStats_; }
  const audio::CallbackStats& renderStatsWithoutSwap() const { return noSwapStats_; }
  const audio::CallbackStats& latencyStats() const { return latencyStats_; }
  /// Whether the convolvers run measured FFT plans (Options::measureFftPlans: from wisdom at
  /// construction, or once measured after the first frame). Any thread; no allocation.
  bool fftPlansMeasured() const { return propagation_->fftPlansMeasured(); }
  /// Head-tracked binaural: head-turn latency, pose published -> first block rendered with it
  /// (the audio thread turns the sound field per block; no propagation frame waited for).
  const audio::CallbackStats& headLatencyStats() const { return headLatencyStats_; }
  bool headTracked() const { return headTracked_; }
  /// Each propagation frame's stages (runtime/frame_profile.h), since the session was built:
  /// trace, pairs, synthesis, partition, publish, snapshot and the whole frame. Any thread;
  /// no allocation.
  FrameProfile::Snapshot frameProfile() const;

  /// After stop(): the recorded output (deviceChannels channels) or empty.
  audio::AudioData takeRecording();
  /// After stop(), recording to options.recordPath: renames the file into place and returns
  /// its frames (Recorder::commit; throws InputError naming the path on a failed write). 0
  /// without such a recording.
  size_t commitRecording();

 private:
  void propagationLoop();
  /// After the first frame (propagation thread): what the first IR did not need, the
  /// synthesisers' completion and the start of the planner thread.
  void afterFirstFrame();
  /// Seconds of a frame that scale with its rays (AdaptiveRays::update).
  static double raysSeconds(const Simulation::FrameTimes& t);
  /// One propagation frame at raysPerSource rays per source (adapt: at the controller's rays
  /// for what its pose's age leaves of the latency budget, AdaptiveRays::raysFor): assemble the
  /// world, trace it, hand the played listener's IR set over, update the counters and the
  /// response snapshot. Propagation thread (or the control thread through step()).
  void runFrame(int raysPerSource, bool adapt = false);
  /// Seconds from an IR set's readiness to its last source group's first block (at most).
  double pickUpSeconds() const;
  /// Propagation thread, before a frame due to end by nextNs (steady ns): waits (polling) for
  /// the host's next pose when the one in hand is stale and the next is due in time for a
  /// frame as long as the last to end by then, or, when it cannot, soon enough to cost little
  /// of the frame rate (runtime/pose_sync.h poseWaitUntilNs).
  void awaitFreshPose(int64_t nextNs);
  /// The frame's statistics after the trace (runFrame).
  void recordFrame(size_t played, bool produced, double frameMs);
  /// Synthesises the played listener's IR set into a free set of the exchange and publishes
  /// it (the pose's publication time stamped for the latency). Returns false when no set was
  /// free (counted: Status::irsLost).
  bool handOver(size_t played, const ListenerPose& pose);
  /// Audio thread: one engine block from the adapter's inputs (nullptr: the scene's signals)
  /// into its outputs. Returns whether an IR swap started.
  bool renderBlock(const float* const* inputs, float* const* outputs) noexcept;
  /// Audio thread: whether any of the device's channels holds a sample other than 0.
  bool holdsSound(float* const* outputs, int frames) const noexcept;
  /// Audio thread: the IR channels onto the device channels (the last repeats), zeros for
  /// a block with NaN or infinity. Returns whether the block was finite.
  bool copyToDevice(float* const* outputs) noexcept;

  std::shared_ptr<const SceneDesc> scene_;
  Options options_;
  int blockSize_, sampleRate_;
  std::unique_ptr<PropagationStage> propagation_;
  std::unique_ptr<IrExchange> exchange_;  ///< the IR sets between the two stages
  std::unique_ptr<AudioStage> audioStage_;
  HostPoses poses_;
  WorldState world_;  ///< propagation thread: this frame's world
  /// Frames whose IR set found no free set (written by the propagation side, read by any).
  std::atomic<uint64_t> framesWithoutSet_{0};
  std::vector<float> mono_;  ///< audio-thread scratch: one block per IR channel
  std::vector<float*> stageOut_;
  CallbackAdapter adapter_;
  /// Last stage before the device: nothing beyond full scale reaches it.
  std::unique_ptr<audio::Limiter> limiter_;
  std::unique_ptr<Recorder> recorder_;  ///< null unless options.recordSeconds > 0
  ResponseSnapshot snapshot_{options_.keepImpulseResponses};

  std::thread propagationThread_;
  /// Options::measureFftPlans without wisdom: measures the convolvers' plans once (started by
  /// the propagation thread after the first frame, joined by stop()).
  std::thread plannerThread_;
  std::atomic<bool> running_{false};
  std::mutex wakeMutex_;
  std::condition_variable wake_;

  mutable SessionCounters counters_;
  AdaptiveRays adaptiveRays_;  ///< propagation thread (or stepAdaptive() while stopped)
  SilenceWatch silence_;       ///< propagation thread: logs when the listener hears nothing
  /// The last IR set's pose publication and readiness, steady_clock ns (propagation thread).
  int64_t lastPoseNs_ = 0, lastReadyNs_ = 0;
  double lastKnownSeconds_ = 0.0;  ///< the last frame's latency known at its start, s
  double lastFrameSeconds_ = 0.0;  ///< the last frame's duration, s (propagation thread)
  audio::CallbackStats swapStats_, noSwapStats_, latencyStats_, headLatencyStats_;
  /// Head-tracked binaural output: the audio thread reads the pose every block.
  bool headTracked_ = false;
  int64_t headPoseNs_ = 0;  ///< publication time of the pose last applied (audio thread)
  /// Audio thread: the played listener's newest orientation into the audio stage.
  void turnHead() noexcept;
};

}  // namespace dpc
