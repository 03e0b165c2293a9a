#include "runtime/live_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "audio/rt_check.h"
#include "common/input_error.h"
#include "common/stopwatch.h"
#include "runtime/output_format.h"
#include "runtime/pose_sync.h"
#include "scene/orientation.h"

namespace dpc {

namespace {

size_t checkedListener(const SceneDesc& scene, size_t listener) {
  if (listener >= scene.listeners.size())
    throw std::out_of_range("LiveSession: listener " + std::to_string(listener) +
                            " is not one of the scene's " + std::to_string(scene.listeners.size()) +
                            " listeners");
  return listener;
}

/// A reuse tolerance of Options, dB in [0, 6].
double checkedToleranceDb(const char* name, double db) {
  if (!(db >= 0.0 && db <= 6.0))
    throw std::invalid_argument(std::string("LiveSession: ") + name + " " + std::to_string(db) +
                                " outside [0, 6]");
  return db;
}

}  // namespace

LiveSession::LiveSession(std::shared_ptr<const SceneDesc> scene,
                         const PropagationSettings& settings, std::shared_ptr<const DrySignals> dry,
                         const Options& options)
    : scene_(std::move(scene)),
      options_(options),
      blockSize_(scene_->audio.blockSize),
      sampleRate_(scene_->audio.sampleRate),
      propagation_(std::make_unique<PropagationStage>(
          scene_, settings,
          options.measureFftPlans ? audio::ConvolverLayout::Planning::kMeasureLater
                                  : audio::ConvolverLayout::Planning::kEstimate,
          options.quickFirstIr ? IrSynthesizer::Build::kFirstIr : IrSynthesizer::Build::kComplete)),
      exchange_(propagation_->makeExchange(1, std::max(3, options.poolSize))),
      audioStage_(std::make_unique<AudioStage>(*propagation_, std::move(dry), *exchange_)),
      poses_(scene_, checkedListener(*scene_, options.listener)),
      adapter_(blockSize_, audioStage_->sourceCount(), options.deviceChannels),
      limiter_(std::make_unique<audio::Limiter>(sampleRate_)),
      counters_(settings.raysPerFrame, AdaptiveRays::floorFor(settings.raysPerFrame)),
      adaptiveRays_(settings.raysPerFrame, 1.0 / settings.frameRate, options.latencyTargetSeconds) {
  if (options.bake) propagation_->attachBake(options.bake);
  propagation_->reuseLateBuses(checkedToleranceDb("lateBusToleranceDb", options.lateBusToleranceDb));
  propagation_->reuseSourceIrs(
      checkedToleranceDb("sourceIrToleranceDb", options.sourceIrToleranceDb));
  propagation_->recordSurfaces(options.keepSurfaceEnergy);
  // A live listener moves: the wave band plays live only from a bake that carries it (each
  // probe's, runtime/propagation_stage.h), never simulated for one pose.
  if (scene_->wave.enabled && !(options.bake && options.bake->hasWave()))
    throw InputError(scene_->path, "wave.enabled",
                     "the wave band is simulated for offline renders (dpc-demo --offline, "
                     "dpc-wave) and played live only from a bake that carries it (dpc-bake with "
                     "wave.enabled): set it to false, or play such a bake");
  if (!(options.irSwapSpreadSeconds >= 0.0 &&
        options.irSwapSpreadSeconds <= kMaxIrSwapSpreadSeconds))
    throw std::invalid_argument("LiveSession: irSwapSpreadSeconds " +
                                std::to_string(options.irSwapSpreadSeconds) + " outside [0, " +
                                std::to_string(kMaxIrSwapSpreadSeconds) + "]");
  audioStage_->setIrSwapSpread(
      std::max(1, int(std::lround(options.irSwapSpreadSeconds * sampleRate_ / blockSize_))));
  const int irChannels = renderedChannels(scene_->audio);
  headTracked_ = scene_->audio.output == OutputFormat::kAmbisonicBinaural;
  mono_.assign(size_t(blockSize_) * size_t(irChannels), 0.f);
  for (int c = 0; c < irChannels; ++c)
    stageOut_.push_back(mono_.data() + size_t(c) * size_t(blockSize_));
  if (options_.recordSeconds > 0.0)
    recorder_ = std::make_unique<Recorder>(sampleRate_, options_.deviceChannels,
                                           options_.recordSeconds, blockSize_, options_.recordPath);
}

int LiveSession::irSwapSpreadBlocks() const {
  return audioStage_->irSwapSpreadBlocks();
}

LiveSession::~LiveSession() {
  stop();
}

void LiveSession::setPose(const glm::vec3& position, float yawRadians, double sceneSeconds,
                          float pitchRadians, float rollRadians) {
  poses_.setListenerPose(poses_.played(), position, yawRadians, sceneSeconds, pitchRadians,
                         rollRadians);
}

bool LiveSession::setListenerPose(size_t index, const glm::vec3& position, float yawRadians,
                                  double sceneSeconds, float pitchRadians, float rollRadians) {
  return poses_.setListenerPose(index, position, yawRadians, sceneSeconds, pitchRadians,
                                rollRadians);
}

void LiveSession::start() {
  if (running_.exchange(true)) return;
  counters_.started(steadyNowNs());
  propagationThread_ = std::thread([this] {
    audio::rt::setThreadRole(audio::rt::ThreadRole::kPropagation);
    propagationLoop();
  });
  if (recorder_) recorder_->start();
}

void LiveSession::stop() {
  if (!running_.exchange(false)) return;
  wake_.notify_all();
  if (propagationThread_.joinable()) propagationThread_.join();
  if (plannerThread_.joinable()) plannerThread_.join();
  if (recorder_) recorder_->stop();
}

bool LiveSession::attachBake(std::shared_ptr<const BakedField> bake) {
  if (running_.load()) return false;
  propagation_->attachBake(std::move(bake));
  return true;
}

bool LiveSession::step() {
  if (running_.load()) return false;
  propagation_->completeSynthesis();  // a stepped session's IRs as a complete build's
  runFrame(settings().raysPerFrame);
  return true;
}

bool LiveSession::stepAdaptive(double frameSeconds) {
  if (running_.load()) return false;
  propagation_->completeSynthesis();
  runFrame(adaptiveRays_.rays());
  adaptiveRays_.update(frameSeconds);
  return true;
}

void LiveSession::awaitFreshPose(int64_t nextNs) {
  ListenerPose held;
  const size_t played = poses_.played();
  if (!poses_.tryListenerPose(played, held)) return;
  // The latest start that lets a frame as long as the last one (and kFrameLengthMargin) end
  // before the next frame is due; a frame that cannot end by then even starting now is overdue.
  const int64_t frameNs = int64_t(lastFrameSeconds_ * 1e9), now = steadyNowNs();
  const int64_t latestNs = nextNs - int64_t(kFrameLengthMargin * double(frameNs));
  const int64_t until = poseWaitUntilNs(held, now, latestNs, now + frameNs > nextNs ? frameNs : 0);
  ListenerPose newest;
  while (steadyNowNs() < until && running_.load(std::memory_order_relaxed)) {
    std::this_thread::sleep_for(std::chrono::nanoseconds(kPosePollNs));
    if (poses_.tryListenerPose(played, newest) && newest.publishedNs != held.publishedNs) return;
  }
}

double LiveSession::pickUpSeconds() const {
  // The audio thread takes a new IR set at its next block, and a staggered swap reaches its
  // last source group that many blocks later.
  return double(audioStage_->irSwapSpreadBlocks()) * blockSize_ / sampleRate_;
}

void LiveSession::runFrame(int raysPerSource, bool adapt) {
  lastPoseNs_ = lastReadyNs_ = 0;  // set by handOver() only if this frame yields an IR set
  const auto t0 = std::chrono::steady_clock::now();
  size_t played = 0;
  const ListenerPose pose = poses_.assemble(world_, played);
  if (adapt) {
    // What this frame's latency already holds before any work: its pose's age, the pick-up.
    const int64_t now = steadyNowNs();
    lastKnownSeconds_ =
        (pose.publishedNs > 0 ? double(now - pose.publishedNs) * 1e-9 : 0.0) + pickUpSeconds();
    raysPerSource = adaptiveRays_.raysFor(lastKnownSeconds_);
  }
  // The estimators normalise by the rays each frame traced, so the count may change per frame.
  propagation_->traceWorld(world_, raysPerSource);
  const bool produced = handOver(played, pose);
  recordFrame(played, produced, secondsSince(t0) * 1e3);
  FrameProfile& profile = propagation_->profile();
  if (produced) {
    // Never waits: a reader holding the snapshot makes this frame skip it.
    const auto t1 = std::chrono::steady_clock::now();
    snapshot_.tryStore(*propagation_, world_, played, counters_.frames());
    profile.record(FrameProfile::kSnapshot, secondsSince(t1));
  }
  profile.record(FrameProfile::kFrame, secondsSince(t0));
}

bool LiveSession::handOver(size_t played, const ListenerPose& pose) {
  const auto t0 = std::chrono::steady_clock::now();
  IrSet* set = exchange_->acquire();
  if (!set) {
    framesWithoutSet_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  const double acquired = secondsSince(t0);
  propagation_->prepare(played, *set);
  const auto t1 = std::chrono::steady_clock::now();
  set->poseNs = pose.publishedNs;
  set->readyNs = steadyNowNs();
  lastPoseNs_ = set->poseNs;
  lastReadyNs_ = set->readyNs;
  exchange_->publish(0, set);
  propagation_->profile().record(FrameProfile::kPublish, acquired + secondsSince(t1));
  return true;
}

FrameProfile::Snapshot LiveSession::frameProfile() const {
  return propagation_->profile().snapshot();
}

void LiveSession::recordFrame(size_t played, bool produced, double frameMs) {
  const Simulation& sim = propagation_->simulation();
  // Rays per source this frame really traced (every source traces the same count).
  if (sim.sourceCount() > 0) counters_.raysTraced(int(sim.result(0, played).trace.rays));
  silence_.update(sim, played, scene_->listeners[played].name, world_.listenerPositions[played],
                  propagation_->bakedPlayback());
  if (!produced) return;
  FrameTotals totals;
  for (size_t s = 0; s < sim.sourceCount(); ++s) totals.add(sim.result(s, played));
  counters_.frameDone(totals, frameMs);
  if (const BakedPlayback* baked = propagation_->bakedPlayback())
    counters_.bakeCounts(baked->stats().bakedResponses, baked->stats().fallbacks);
}

void LiveSession::propagationLoop() {
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / settings().frameRate));
  auto next = std::chrono::steady_clock::now();
  for (bool first = true; running_.load(std::memory_order_relaxed); first = false) {
    next += period;
    if (!first)
      awaitFreshPose(
          std::chrono::duration_cast<std::chrono::nanoseconds>(next.time_since_epoch()).count());
    const auto start = std::chrono::steady_clock::now();
    // The first frame traces the controller's first rays (a quarter of the scene's): the first
    // sound comes that much sooner, and the cache's estimate is unbiased at any ray count (its
    // noise then falls as the following frames, at the controller's rays, add theirs).
    const bool adapt = options_.adaptiveRays && !first;
    runFrame(options_.adaptiveRays ? adaptiveRays_.rays() : settings().raysPerFrame, adapt);
    if (first) afterFirstFrame();  // outside the controller's frame time
    // The whole frame, snapshot included: what must fit in the period; and its pose's age when
    // the IR was ready plus one block (the audio thread picks it up at its next block) and the
    // blocks a staggered swap takes to reach its last source group: the motion-to-sound
    // latency it will have, as renderBlock measures it. The short first frame says nothing
    // about the controller's rays.
    lastFrameSeconds_ =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (adapt) {
      const double latency = lastPoseNs_ > 0
                                 ? double(lastReadyNs_ - lastPoseNs_) * 1e-9 + pickUpSeconds()
                                 : std::nan("");
      adaptiveRays_.update(lastFrameSeconds_, latency,
                           raysSeconds(propagation_->simulation().frameTimes()), lastKnownSeconds_);
    }
    // At most frame_rate frames per second; run late frames back to back.
    std::unique_lock<std::mutex> lock(wakeMutex_);
    if (std::chrono::steady_clock::now() < next)
      wake_.wait_until(lock, next, [this] { return !running_.load(std::memory_order_relaxed); });
    else
      next = std::chrono::steady_clock::now();
  }
}

double LiveSession::raysSeconds(const Simulation::FrameTimes& t) {
  // The tracing, and the pairs' cache updates (their share of the pairs' CPU time): what the
  // rays' count scales. The direct sound, diffraction and exact paths do not.
  const double cpu = t.directCpu + t.exactCpu + t.estimatorCpu;
  return t.trace + (cpu > 0.0 ? t.pairs * t.estimatorCpu / cpu : 0.0);
}

void LiveSession::afterFirstFrame() {
  // The first IR is on its way to the device: now what the following IRs need
  // (Options::quickFirstIr).
  if (!propagation_->synthesisCompleted()) {
    const auto completing = std::chrono::steady_clock::now();
    propagation_->completeSynthesis();
    counters_.synthesisCompleted(secondsSince(completing));
  }
  if (!options_.measureFftPlans || propagation_->fftPlansMeasured() || plannerThread_.joinable())
    return;
  plannerThread_ = std::thread([this] {
    audio::rt::setThreadRole(audio::rt::ThreadRole::kWorker);
    try {
      propagation_->measureFftPlans();
    } catch (const std::exception&) {
      // FFTW could not measure: the estimated plans stay (slower callbacks, the same sound),
      // counted for the session's status.
      counters_.fftPlanFailed();
    }
  });
}

void LiveSession::renderCallback(void* user, float* const* out, int frames) noexcept {
  static_cast<LiveSession*>(user)->render(nullptr, out, frames);
}

void LiveSession::render(const float* const* inputs, float* const* outputs, int frames) noexcept {
  audio::rt::enterAudioThread();
  if (frames < 1 || frames > kMaxCallbackFrames) {
    counters_.rejectedCallback();
    return;
  }
  const int64_t t0 = steadyNowNs();
  const bool swapped = adapter_.run(
      inputs, outputs, frames,
      [this](const float* const* in, float* const* out) { return renderBlock(in, out); });
  if (!counters_.soundHeard() && holdsSound(outputs, frames)) counters_.heard(t0);
  const int64_t ns = steadyNowNs() - t0;
  if (double(ns) * 1e-9 * sampleRate_ > double(frames)) counters_.lateCallback(t0, ns);
  (swapped ? swapStats_ : noSwapStats_).record(uint64_t(ns), false);
}

bool LiveSession::holdsSound(float* const* outputs, int frames) const noexcept {
  for (int c = 0; c < options_.deviceChannels; ++c)
    for (int i = 0; i < frames; ++i)
      if (outputs[c][i] != 0.f) return true;
  return false;
}

bool LiveSession::copyToDevice(float* const* outputs) noexcept {
  const size_t irChannels = stageOut_.size();
  const size_t B = size_t(blockSize_);
  bool finite = true;
  for (size_t i = 0; i < B * irChannels; ++i) finite = finite && std::isfinite(mono_[i]);
  for (int c = 0; c < options_.deviceChannels; ++c) {
    const float* src = stageOut_[std::min(size_t(c), irChannels - 1)];
    if (finite)
      std::copy(src, src + B, outputs[c]);
    else
      std::fill(outputs[c], outputs[c] + B, 0.f);
  }
  return finite;
}

void LiveSession::turnHead() noexcept {
  ListenerPose pose;
  if (!poses_.tryListenerPose(poses_.played(), pose)) return;  // keep the last orientation
  audioStage_->setHeadOrientation(
      Orientation{pose.yawRadians, pose.pitchRadians, pose.rollRadians});
  if (pose.publishedNs == headPoseNs_) return;
  // Pose published -> the first block rendered with it (the block leaves the callback next).
  if (headPoseNs_ != 0)
    headLatencyStats_.record(uint64_t(std::max<int64_t>(0, steadyNowNs() - pose.publishedNs)),
                             false);
  headPoseNs_ = pose.publishedNs;
}

bool LiveSession::renderBlock(const float* const* inputs, float* const* outputs) noexcept {
  if (headTracked_) turnHead();
  const uint64_t appliedBefore = audioStage_->irsApplied();
  audioStage_->process(stageOut_.data(), inputs);
  if (inputs) counters_.inputSamplesReplaced(audioStage_->replacedInputSamples());
  const bool swapped = audioStage_->irsApplied() != appliedBefore;
  const bool finite = copyToDevice(outputs);
  limiter_->process(outputs, options_.deviceChannels, size_t(blockSize_));
  // The recording holds the engine's blocks (what the device plays, without the adapter's
  // leading block of silence).
  if (recorder_) recorder_->push(outputs, blockSize_);
  const int64_t t1 = steadyNowNs();
  double irAgeMs = -1.0;
  if (const IrSet* cur = audioStage_->current()) {
    irAgeMs = double(t1 - cur->readyNs) * 1e-6;
    // Until the last source group has the new set (a staggered swap reaches it that many
    // blocks later).
    const int64_t spreadNs = int64_t(double(audioStage_->irSwapSpreadBlocks() - 1) *
                                     double(blockSize_) / sampleRate_ * 1e9);
    if (swapped)
      latencyStats_.record(uint64_t(std::max<int64_t>(0, t1 + spreadNs - cur->poseNs)), false);
  }
  counters_.blockDone(finite, audioStage_->irsApplied(), irAgeMs);
  return swapped;
}

LiveSession::Status LiveSession::status() const {
  Status st;
  counters_.read(st);
  const auto lat = latencyStats_.snapshot();
  st.latencyMedianMs = lat.callbacks ? double(lat.quantileNs(0.5)) * 1e-6 : 0.0;
  st.latencyP95Ms = lat.callbacks ? double(lat.quantileNs(0.95)) * 1e-6 : 0.0;
  st.irsLost = framesWithoutSet_.load(std::memory_order_relaxed);
  st.irsDropped = exchange_->superseded();
  st.stalePartitions = audioStage_->stalePartitions();
  st.recordDropped = recorder_ ? recorder_->droppedSamples() : 0;
  st.limitedFrames = limiter_->limitedFrames();
  st.overCeilingFrames = limiter_->overCeilingFrames();
  st.limiterMaxReductionDb = limiter_->maxReductionDb();
  return st;
}

HybridReport LiveSession::hybridReport() const {
  const HybridSynthesis* hybrid = propagation_->hybrid();
  return hybrid ? hybrid->report(playedListener()) : HybridReport{};
}

KeptIrs::Counts LiveSession::sourceIrCounts() const {
  return propagation_->sourceIrCounts(playedListener());
}

size_t LiveSession::commitRecording() {
  return recorder_ && !running_.load() ? recorder_->commit() : 0;
}

audio::AudioData LiveSession::takeRecording() {
  if (!recorder_ || running_.load()) {
    audio::AudioData a;
    a.sampleRate = sampleRate_;
    return a;
  }
  return recorder_->take();
}

}  // namespace dpc
