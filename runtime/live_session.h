// LiveSession: the live pipeline. The same PropagationStage and AudioStage as offline
// rendering, on three threads (docs/design.md "Thread roles"):
//
//   control thread     setPose() (trajectory or keyboard), status(), start()/stop()
//   propagation thread reads every listener's pose (one PoseChannel each), traces all
//                      listeners in one pass, prepares the played listener's IrSet, pushes
//                      its pointer to the audio thread (SPSC queue), recycles spent sets
//   audio thread       render(): pops at most the newest IrSet per block (older ones go
//                      straight back), convolves and crossfades, mixes, counts problems in
//                      relaxed atomics, feeds the recorder ring
//
// Queues: moodycamel::ReaderWriterQueue with fixed capacity (try_enqueue / try_dequeue only:
// never allocate after construction). The recorder ring is boost::lockfree::spsc_queue, drained
// by a recorder thread that writes the WAV at stop().
// render() never allocates, locks, logs, throws, waits or makes system calls (steady_clock is
// the vDSO); tests/rt checks it with an interposed allocator.
#pragma once

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "audio/audio_device.h"
#include "audio/limiter.h"
#include "runtime/adaptive_rays.h"
#include "runtime/pose_channel.h"
#include "runtime/render_pipeline.h"
#include "runtime/spsc_queue.h"

namespace dpc {

class LiveSession {
 public:
  struct Options {
    int deviceChannels = 2;      ///< output channels the device renders (IR channels copied)
    double recordSeconds = 0.0;  ///< > 0: keep what was played (ring of this many seconds)
    int poolSize = 6;            ///< IrSets in flight (>= 3)
    /// The propagation thread adapts the rays per source of each frame to hold the frame
    /// rate (runtime/adaptive_rays.h, docs/live.md "Adaptive rays"): fewer rays when a frame
    /// takes longer than 1 / frame_rate, back up to the settings' rays when there is room.
    /// false: every frame traces the settings' rays, however long it takes.
    bool adaptiveRays = true;
    /// Motion-to-sound latency the adaptive rays aim under, seconds (pose published -> IR
    /// ready, plus one block for the audio thread to pick it up). Infinite: the frame period
    /// alone bounds the rays.
    double latencyTargetSeconds = 0.05;
  };

  /// Control thread. Builds the stages (Embree scene, IR synthesisers, convolvers, queues).
  /// Allocates; throws on bad input. blockSize comes from scene.audio.blockSize.
  LiveSession(const SceneDesc& scene, const PropagationSettings& settings, const DrySignals& dry,
              const Options& options);
  ~LiveSession();

  /// Control thread: starts the propagation (and recorder) threads. The audio device, created
  /// by the caller, calls render() from its audio thread.
  void start();
  /// Control thread: stops and joins the threads. Idempotent.
  void stop();

  /// Any thread (one writer at a time): publishes a new pose (timestamped now) for the played
  /// listener (playedListener()). Yaw and pitch as in dpc::Orientation (radians; yaw 0 faces
  /// +x, positive turns left). Wait-free; no allocation.
  void setPose(const glm::vec3& position, float yawRadians, double sceneSeconds,
               float pitchRadians = 0.f);
  /// Any thread (one writer per listener at a time): publishes listener `index`'s pose
  /// (scene.listeners order; index 0 only when the scene lists none), timestamped now, for the
  /// following propagation frames. Every listener is traced each frame in the same pass (its
  /// cache stays current whether it is played or not); until a pose is published a listener
  /// stands where its trajectory puts it at t = 0. sceneSeconds: the scene time the pose
  /// belongs to (sources and objects follow their trajectories at the played listener's
  /// time). Returns false (and changes nothing) for an index out of range. Wait-free (seqlock,
  /// runtime/pose_channel.h); no allocation.
  bool setListenerPose(size_t index, const glm::vec3& position, float yawRadians,
                       double sceneSeconds, float pitchRadians = 0.f);
  /// Any thread: plays listener `index` from the next propagation frame on (the audio thread
  /// crossfades to its IR like to any new IR). False for an index out of range. Wait-free.
  bool selectListener(size_t index);
  /// The listener being played (scene.listeners order).
  size_t playedListener() const { return played_.load(std::memory_order_relaxed); }
  /// Listeners traced every frame: scene.listeners.size(), or 1 when the scene lists none.
  size_t listenerCount() const { return listenerCount_; }
  /// Any thread (one writer per source at a time): places source `index` (scene order) at
  /// `position` (m) from the next propagation frame on, instead of its trajectory. Returns false
  /// (and changes nothing) for an index out of range. Wait-free; no allocation.
  bool setSourcePosition(size_t index, const glm::vec3& position);
  /// Any thread (one writer per object at a time): object `index` at world = R(rotation) *
  /// local + position; rotation a unit quaternion (x, y, z, w), normalised here; false for an
  /// index out of range or a zero-length rotation. Wait-free; no allocation.
  bool setObjectPose(size_t index, const glm::vec3& position, const float rotation[4]);
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

  /// The newest frame's responses for one source, as copied by the propagation thread after
  /// each frame: ir[channel][sample] the pressure IR at sampleRate(); energy[k][band] the
  /// energy response in bins of binSeconds (1/m^2 relative to source power, direct sound
  /// included); frame = propagation frames run when it was taken.
  struct Responses {
    const std::vector<std::vector<float>>* ir;
    const std::vector<Bands>* energy;
    double binSeconds;
    uint64_t frame;
  };
  /// Any thread but the audio thread: calls f with the newest responses of `source` while
  /// holding the snapshot lock (the propagation thread skips its copy rather than wait for
  /// it). Returns false, without calling f, before the first frame or for a bad index.
  /// Allocates nothing itself (f is called directly, not through a type-erased wrapper).
  template <class F>
  bool copyResponses(size_t source, F&& f) {
    std::lock_guard<std::mutex> lock(snapshotMutex_);
    if (!snapshotValid_ || source >= snapshotIrs_.size()) return false;
    f(Responses{&snapshotIrs_[source], &snapshotEnergy_[source], snapshotBinSeconds_,
                snapshotFrame_});
    return true;
  }

  /// IR channels (1 mono, 2 stereo/binaural).
  int irChannels() const { return int(stageOut_.size()); }

  /// Audio thread: renders `frames` frames (any count from 1 to kMaxCallbackFrames, varying
  /// from call to call) into outputs[0..deviceChannels). The engine works in fixed blocks of
  /// blockSize() frames; a FIFO adapter between the host's calls and those blocks adds a
  /// constant latency of adapterLatencyFrames() = blockSize() frames for every call pattern:
  /// output sample t (counted from the first call) is engine output sample t - blockSize()
  /// (zeros before). inputs: nullptr renders the scene's own dry signals; otherwise
  /// inputs[s][0..frames) is the host's dry input for source s (one mono channel per scene
  /// source, same order as scene.sources), delayed by the same adapter latency.
  /// Calls with frames < 1 or > kMaxCallbackFrames render nothing and are counted
  /// (Status::rejectedCallbacks). Wait-free; no allocation, locks, logging, exceptions or
  /// system calls.
  void render(const float* const* inputs, float* const* outputs, int frames) noexcept;
  /// render(nullptr, outputs, frames): the scene's own dry signals.
  void render(float* const* outputs, int frames) noexcept { render(nullptr, outputs, frames); }
  /// Adapter with the audio::RenderCallback signature (user = LiveSession*; nullptr inputs).
  static void renderCallback(void* user, float* const* out, int frames) noexcept;

  /// Largest host callback render() accepts, frames.
  static constexpr int kMaxCallbackFrames = 8192;
  /// Latency added by the callback-size adapter, frames (constant: one engine block).
  int adapterLatencyFrames() const { return blockSize_; }
  /// Dry inputs render() expects when the host provides them (the scene's source count).
  int sourceCount() const { return int(hostIn_.size()); }

  int blockSize() const { return blockSize_; }
  int sampleRate() const { return sampleRate_; }

  struct Status {
    uint64_t frames = 0;
    double frameMs = 0.0;        ///< last propagation frame (trace + synthesis + prepare)
    double raysPerSecond = 0.0;  ///< over the last status interval
    /// Rays per source traced by the last frame (0 before the first); below raysPerFrameScene
    /// when the adaptive controller reduced them to hold the frame rate.
    int raysPerFrame = 0;
    int raysPerFrameMin = 0;          ///< fewest rays per source of any frame so far (0: none yet)
    int raysPerFrameScene = 0;        ///< the settings' rays per source (the controller's ceiling)
    uint64_t reducedFrames = 0;       ///< frames traced with fewer rays than raysPerFrameScene
    size_t cacheEntries = 0;          ///< DPC path + coarse entries, summed over sources
    size_t cacheBytes = 0;            ///< DPC heap bytes, summed over sources
    size_t cacheBudgetBytes = 0;      ///< DPC memory budget, summed over sources
    uint64_t cacheMergedEntries = 0;  ///< entries merged into the coarse store, cumulative
    double cacheMergedEnergyFraction =
        0.0;                       ///< largest per-source share of the response they carry
    uint64_t irsApplied = 0;       ///< IR sets that reached the convolvers
    uint64_t irsDropped = 0;       ///< superseded before the audio thread applied them
    double irAgeMs = 0.0;          ///< age of the IR playing, at the last block
    double latencyMedianMs = 0.0;  ///< motion-to-sound latency, since start
    double latencyP95Ms = 0.0;
    uint64_t blocks = 0;
    uint64_t nanBlocks = 0;          ///< blocks zeroed by the NaN/inf guard
    uint64_t lateCallbacks = 0;      ///< render() calls that took longer than the audio they
                                     ///< produced (frames / sampleRate): a device would xrun
    uint64_t rejectedCallbacks = 0;  ///< render() calls with frames outside 1..kMaxCallbackFrames
    uint64_t recordDropped = 0;      ///< samples the recorder ring could not take
    /// Output safety limiter (audio/limiter.h), since start: frames it attenuated, frames
    /// whose input exceeded its ceiling, and its largest gain reduction (dB).
    uint64_t limitedFrames = 0;
    uint64_t overCeilingFrames = 0;
    float limiterMaxReductionDb = 0.f;
  };
  Status status() const;

  /// Durations of render() per block, split by whether an IR swap (crossfade) happened.
  const audio::CallbackStats& renderStatsWithSwap() const { return swapStats_; }
  const audio::CallbackStats& renderStatsWithoutSwap() const { return noSwapStats_; }
  const audio::CallbackStats& latencyStats() const { return latencyStats_; }

  /// After stop(): the recorded output (deviceChannels channels) or empty.
  audio::AudioData takeRecording();

 private:
  void propagationLoop();
  /// One propagation frame at raysPerSource rays per source: read the poses, compute, hand the IR
  /// set over, update the counters and the response snapshot. Propagation thread (or the control
  /// thread through step()).
  void runFrame(int raysPerSource);
  /// Audio thread: one engine block from blockIn_ (or the scene's signals) into blockOut_.
  /// Returns whether an IR swap started.
  bool renderBlock(bool hostInputs) noexcept;
  void recorderLoop();

  const SceneDesc& scene_;
  PropagationSettings settings_;
  Options options_;
  int blockSize_, sampleRate_;
  std::unique_ptr<PropagationStage> propagation_;
  std::unique_ptr<AudioStage> audioStage_;
  size_t listenerCount_ = 1;
  std::unique_ptr<PoseChannel[]> poses_;  ///< one per listener
  std::atomic<size_t> played_{0};
  WorldState world_;  ///< propagation thread: this frame's poses
  std::unique_ptr<SeqlockChannel<HostSourcePosition>[]> hostSources_;
  std::unique_ptr<SeqlockChannel<HostObjectPose>[]> hostObjects_;
  moodycamel::ReaderWriterQueue<IrSet*> toAudio_, fromAudio_;
  std::vector<float> mono_;  ///< audio-thread scratch: one block per IR channel
  std::vector<float*> stageOut_;
  // Callback-size adapter (audio thread): the host's inputs of the engine block being filled
  // (one block per source) and the device-channel output of the last engine block, read out
  // while the next one fills. fill_ = frames of the current block filled so far.
  std::vector<std::vector<float>> hostIn_;
  std::vector<const float*> hostInPtr_;
  std::vector<std::vector<float>> blockOut_;
  std::vector<float*> blockOutPtr_;
  /// Last stage before the device: nothing beyond full scale reaches it.
  std::unique_ptr<audio::Limiter> limiter_;
  int fill_ = 0;
  std::unique_ptr<boost::lockfree::spsc_queue<float>> recordRing_;
  std::vector<float> recordScratch_;
  std::vector<std::vector<float>> recorded_;

  // Snapshot of the newest frame's responses (runFrame writes it under try_lock).
  std::mutex snapshotMutex_;
  std::vector<std::vector<std::vector<float>>> snapshotIrs_;  ///< [source][channel][sample]
  std::vector<std::vector<Bands>> snapshotEnergy_;            ///< [source][bin]
  double snapshotBinSeconds_ = 0.0;
  uint64_t snapshotFrame_ = 0;
  bool snapshotValid_ = false;

  std::thread propagationThread_, recorderThread_;
  std::atomic<bool> running_{false};
  std::mutex wakeMutex_;
  std::condition_variable wake_;

  // Statistics: written by one thread, read by the control thread (relaxed).
  std::atomic<uint64_t> frames_{0}, rays_{0}, irsDropped_{0}, blocks_{0}, nanBlocks_{0},
      lateCallbacks_{0}, rejectedCallbacks_{0}, recordDropped_{0}, irsApplied_{0};
  std::atomic<double> frameMs_{0.0}, irAgeMs_{0.0};
  std::atomic<size_t> cacheEntries_{0}, cacheBytes_{0}, cacheBudgetBytes_{0};
  std::atomic<uint64_t> cacheMergedEntries_{0};
  std::atomic<double> cacheMergedEnergyFraction_{0.0};
  AdaptiveRays adaptiveRays_;  ///< propagation thread (or stepAdaptive() while stopped)
  /// The last IR set's pose publication and readiness, steady_clock ns (propagation thread).
  int64_t lastPoseNs_ = 0, lastReadyNs_ = 0;
  std::atomic<int> raysPerFrame_{0}, raysPerFrameMin_{0};
  std::atomic<uint64_t> reducedFrames_{0};
  mutable uint64_t lastRays_ = 0;
  mutable std::chrono::steady_clock::time_point lastStatus_{};
  audio::CallbackStats swapStats_, noSwapStats_, latencyStats_;
};

/// A stand-in audio device for machines without one (benchmarks, tests): a thread that calls
/// the render callback every block period on a steady clock, like a sound card would.
/// Control thread: construct, start, stop. Its thread is the "audio thread".
class NullOutput {
 public:
  NullOutput(int sampleRate, int blockSize, int channels, audio::RenderCallback cb, void* user);
  ~NullOutput();
  void start();
  void stop();
  const audio::CallbackStats& stats() const { return stats_; }

 private:
  int sampleRate_, blockSize_, channels_;
  audio::RenderCallback callback_;
  void* user_;
  std::vector<std::vector<float>> buffers_;
  std::vector<float*> pointers_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  audio::CallbackStats stats_;
};

}  // namespace dpc
