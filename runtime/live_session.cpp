#include "runtime/live_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace dpc {

namespace {

int64_t nowNs() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

constexpr double kRecordRingSeconds = 2.0;

}  // namespace

LiveSession::LiveSession(const SceneDesc& scene, const PropagationSettings& settings,
                         const DrySignals& dry, const Options& options)
    : scene_(scene),
      settings_(settings),
      options_(options),
      blockSize_(scene.audio.blockSize),
      sampleRate_(scene.audio.sampleRate),
      toAudio_(size_t(std::max(3, options.poolSize)) + 1),
      fromAudio_(size_t(std::max(3, options.poolSize)) + 1),
      adaptiveRays_(settings.raysPerFrame, 1.0 / settings.frameRate,
                    options.latencyTargetSeconds) {
  propagation_ = std::make_unique<PropagationStage>(scene, settings, std::max(3, options.poolSize));
  // Every listener is traced each frame; each starts where its trajectory is at t = 0.
  listenerCount_ = std::max<size_t>(1, scene.listeners.size());
  poses_ = std::make_unique<PoseChannel[]>(listenerCount_);
  for (size_t l = 0; l < listenerCount_; ++l) {
    const ListenerDesc& d = scene.listeners.empty() ? scene.listener : scene.listeners[l];
    const Orientation o = listenerOrientationAt(d, 0.0);
    poses_[l].publish(
        ListenerPose{listenerPositionAt(d, 0.0), o.yawRadians, o.pitchRadians, nowNs(), 0.0});
    if (d.name == scene.listener.name) played_.store(l, std::memory_order_relaxed);
  }
  // Room in either queue for every set of the pool (more than poolSize with several partition
  // levels), so try_enqueue never fails for want of space.
  toAudio_ = moodycamel::ReaderWriterQueue<IrSet*>(size_t(propagation_->poolSize()) + 1);
  fromAudio_ = moodycamel::ReaderWriterQueue<IrSet*>(size_t(propagation_->poolSize()) + 1);
  hostSources_ = std::make_unique<SeqlockChannel<HostSourcePosition>[]>(scene.sources.size());
  hostObjects_ = std::make_unique<SeqlockChannel<HostObjectPose>[]>(scene.objects.size());
  const int irChannels = propagation_->numOutputs();
  audioStage_ = std::make_unique<AudioStage>(propagation_->layout(), dry, irChannels);
  mono_.assign(size_t(blockSize_) * irChannels, 0.f);
  for (int c = 0; c < irChannels; ++c) stageOut_.push_back(mono_.data() + size_t(c) * blockSize_);
  hostIn_.assign(size_t(audioStage_->sourceCount()), std::vector<float>(size_t(blockSize_), 0.f));
  for (auto& ch : hostIn_) hostInPtr_.push_back(ch.data());
  blockOut_.assign(size_t(options_.deviceChannels), std::vector<float>(size_t(blockSize_), 0.f));
  for (auto& ch : blockOut_) blockOutPtr_.push_back(ch.data());
  limiter_ = std::make_unique<audio::Limiter>(sampleRate_);
  if (options_.recordSeconds > 0.0) {
    recordRing_ = std::make_unique<boost::lockfree::spsc_queue<float>>(
        size_t(kRecordRingSeconds * sampleRate_) * size_t(options_.deviceChannels));
    recordScratch_.assign(size_t(blockSize_) * size_t(options_.deviceChannels), 0.f);
    recorded_.assign(size_t(options_.deviceChannels), {});
    for (auto& ch : recorded_) ch.reserve(size_t(options_.recordSeconds * sampleRate_));
  }
  lastStatus_ = std::chrono::steady_clock::now();
}

LiveSession::~LiveSession() {
  stop();
}

bool LiveSession::setSourcePosition(size_t index, const glm::vec3& position) {
  if (index >= scene_.sources.size()) return false;
  hostSources_[index].publish(HostSourcePosition{position, 1u});
  return true;
}

bool LiveSession::setObjectPose(size_t index, const glm::vec3& position, const float rotation[4]) {
  if (index >= scene_.objects.size()) return false;
  const double n = std::sqrt(double(rotation[0]) * rotation[0] + double(rotation[1]) * rotation[1] +
                             double(rotation[2]) * rotation[2] + double(rotation[3]) * rotation[3]);
  if (!(n > 1e-6) || !std::isfinite(n)) return false;
  HostObjectPose h;
  h.position = position;
  for (int i = 0; i < 4; ++i) h.rotation[i] = float(rotation[i] / n);
  h.set = 1u;
  hostObjects_[index].publish(h);
  return true;
}

void LiveSession::setPose(const glm::vec3& position, float yawRadians, double sceneSeconds,
                          float pitchRadians) {
  setListenerPose(played_.load(std::memory_order_relaxed), position, yawRadians, sceneSeconds,
                  pitchRadians);
}

bool LiveSession::setListenerPose(size_t index, const glm::vec3& position, float yawRadians,
                                  double sceneSeconds, float pitchRadians) {
  if (index >= listenerCount_) return false;
  poses_[index].publish(ListenerPose{position, yawRadians, pitchRadians, nowNs(), sceneSeconds});
  return true;
}

bool LiveSession::selectListener(size_t index) {
  if (index >= listenerCount_) return false;
  played_.store(index, std::memory_order_relaxed);
  return true;
}

void LiveSession::start() {
  if (running_.exchange(true)) return;
  propagationThread_ = std::thread([this] { propagationLoop(); });
  if (recordRing_) recorderThread_ = std::thread([this] { recorderLoop(); });
}

void LiveSession::stop() {
  if (!running_.exchange(false)) return;
  wake_.notify_all();
  if (propagationThread_.joinable()) propagationThread_.join();
  if (recorderThread_.joinable()) recorderThread_.join();
}

bool LiveSession::step() {
  if (running_.load()) return false;
  runFrame(settings_.raysPerFrame);
  return true;
}

bool LiveSession::stepAdaptive(double frameSeconds) {
  if (running_.load()) return false;
  runFrame(adaptiveRays_.rays());
  adaptiveRays_.update(frameSeconds);
  return true;
}

void LiveSession::runFrame(int raysPerSource) {
  // The estimators normalise by the rays each frame traced, so the count may change per frame.
  if (raysPerSource != propagation_->simulation().settings().raysPerFrame)
    propagation_->setRaysPerFrame(raysPerSource);
  IrSet* back = nullptr;
  while (fromAudio_.try_dequeue(back)) propagation_->recycle(back);
  lastPoseNs_ = lastReadyNs_ = 0;  // set below only if this frame yields an IR set
  const auto t0 = std::chrono::steady_clock::now();
  // Every listener's pose; sources and objects at the played listener's scene time.
  const size_t played = played_.load(std::memory_order_relaxed);
  ListenerPose pose;
  world_.listenerPositions.resize(listenerCount_);
  world_.listenerOrientations.resize(listenerCount_);
  for (size_t l = 0; l < listenerCount_; ++l) {
    const ListenerPose p = poses_[l].read();
    world_.listenerPositions[l] = p.position;
    world_.listenerOrientations[l].yawRadians = p.yawRadians;
    world_.listenerOrientations[l].pitchRadians = p.pitchRadians;
    if (l == played) pose = p;
  }
  world_.timeSeconds = pose.sceneSeconds;
  world_.sourcePositions.resize(scene_.sources.size());
  for (size_t i = 0; i < scene_.sources.size(); ++i)
    world_.sourcePositions[i] = sourcePositionAt(scene_.sources[i], pose.sceneSeconds);
  world_.objectPoses.resize(scene_.objects.size());
  for (size_t k = 0; k < scene_.objects.size(); ++k)
    world_.objectPoses[k] = objectPoseAt(scene_.objects[k], pose.sceneSeconds);
  for (size_t i = 0; i < scene_.sources.size(); ++i)
    if (const HostSourcePosition h = hostSources_[i].read(); h.set)
      propagation_->overrideSource(i, h.position);
  for (size_t i = 0; i < scene_.objects.size(); ++i)
    if (const HostObjectPose h = hostObjects_[i].read(); h.set)
      propagation_->overrideObject(i, Pose{h.position, glm::quat(h.rotation[3], h.rotation[0],
                                                                 h.rotation[1], h.rotation[2])});
  propagation_->traceWorld(world_);
  IrSet* set = propagation_->prepare(played);
  const auto t1 = std::chrono::steady_clock::now();
  // Rays per source this frame really traced (every source traces the same count).
  if (propagation_->simulation().sourceCount() > 0) {
    const int traced = int(propagation_->simulation().result(0, played).trace.rays);
    raysPerFrame_.store(traced, std::memory_order_relaxed);
    const int low = raysPerFrameMin_.load(std::memory_order_relaxed);
    if (low == 0 || traced < low) raysPerFrameMin_.store(traced, std::memory_order_relaxed);
    if (traced < settings_.raysPerFrame) reducedFrames_.fetch_add(1, std::memory_order_relaxed);
  }
  if (set) {
    set->poseNs = pose.publishedNs;
    set->readyNs = nowNs();
    lastPoseNs_ = set->poseNs;
    lastReadyNs_ = set->readyNs;
    if (!toAudio_.try_enqueue(set)) {
      propagation_->recycle(set);
      irsDropped_.fetch_add(1, std::memory_order_relaxed);
    }
    frames_.fetch_add(1, std::memory_order_relaxed);
    uint64_t rays = 0;
    size_t entries = 0, bytes = 0, budget = 0;
    uint64_t merged = 0;
    double mergedShare = 0.0;
    for (size_t s = 0; s < propagation_->simulation().sourceCount(); ++s) {
      const Simulation::SourceResult& sr = propagation_->simulation().result(s, played);
      rays += sr.trace.rays;
      entries += sr.cacheEntries + sr.cacheCoarseEntries;
      bytes += sr.cacheBytes;
      budget += sr.cacheBudgetBytes;
      merged += sr.cacheMergedEntries;
      mergedShare = std::max(mergedShare, sr.cacheCoarseEnergyFraction);
    }
    cacheBytes_.store(bytes, std::memory_order_relaxed);
    cacheBudgetBytes_.store(budget, std::memory_order_relaxed);
    cacheMergedEntries_.store(merged, std::memory_order_relaxed);
    cacheMergedEnergyFraction_.store(mergedShare, std::memory_order_relaxed);
    rays_.fetch_add(rays, std::memory_order_relaxed);
    cacheEntries_.store(entries, std::memory_order_relaxed);
    frameMs_.store(std::chrono::duration<double, std::milli>(t1 - t0).count(),
                   std::memory_order_relaxed);
  }
  // Snapshot of this frame's responses for readers on other threads (copyResponses). Never
  // waits: a reader holding the lock makes this frame skip its snapshot.
  if (set) {
    std::unique_lock<std::mutex> lock(snapshotMutex_, std::try_to_lock);
    if (lock.owns_lock()) {
      const Simulation& sim = propagation_->simulation();
      snapshotIrs_ = propagation_->lastIrs();
      snapshotEnergy_.resize(sim.sourceCount());
      for (size_t s = 0; s < sim.sourceCount(); ++s) {
        const Simulation::SourceResult& r = sim.result(s, played);
        snapshotEnergy_[s] = r.energy.bins();
        // The direct sound (with its diffraction) is computed apart from the estimator's bins.
        const double k = r.direct.delaySeconds / r.energy.binSeconds();
        if (k >= 0.0 && k < double(snapshotEnergy_[s].size()))
          snapshotEnergy_[s][size_t(k)] += r.direct.intensity;
      }
      snapshotBinSeconds_ = Simulation::kEnergyBinSeconds;
      snapshotFrame_ = frames_.load(std::memory_order_relaxed);
      snapshotValid_ = true;
    }
  }
}

void LiveSession::propagationLoop() {
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / settings_.frameRate));
  auto next = std::chrono::steady_clock::now();
  while (running_.load(std::memory_order_relaxed)) {
    next += period;
    const auto start = std::chrono::steady_clock::now();
    runFrame(options_.adaptiveRays ? adaptiveRays_.rays() : settings_.raysPerFrame);
    // The whole frame, snapshot included: what must fit in the period; and its pose's age when
    // the IR was ready plus one block (the audio thread picks it up at its next block): the
    // motion-to-sound latency it will have.
    if (options_.adaptiveRays) {
      const double latency = lastPoseNs_ > 0 ? double(lastReadyNs_ - lastPoseNs_) * 1e-9 +
                                                   double(blockSize_) / sampleRate_
                                             : std::nan("");
      adaptiveRays_.update(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
          latency);
    }
    // At most frame_rate frames per second; run late frames back to back.
    std::unique_lock<std::mutex> lock(wakeMutex_);
    if (std::chrono::steady_clock::now() < next)
      wake_.wait_until(lock, next, [this] { return !running_.load(std::memory_order_relaxed); });
    else
      next = std::chrono::steady_clock::now();
  }
}

void LiveSession::recorderLoop() {
  std::vector<float> buf(size_t(0.05 * sampleRate_) * size_t(options_.deviceChannels));
  const size_t channels = size_t(options_.deviceChannels);
  size_t phase = 0;  // channel of the next sample (the ring is interleaved)
  auto drain = [&] {
    size_t n;
    while ((n = recordRing_->pop(buf.data(), buf.size())) > 0)
      for (size_t i = 0; i < n; ++i) {
        recorded_[phase].push_back(buf[i]);
        phase = (phase + 1) % channels;
      }
  };
  while (running_.load(std::memory_order_relaxed)) {
    drain();
    std::unique_lock<std::mutex> lock(wakeMutex_);
    wake_.wait_for(lock, std::chrono::milliseconds(10),
                   [this] { return !running_.load(std::memory_order_relaxed); });
  }
  drain();
}

void LiveSession::renderCallback(void* user, float* const* out, int frames) noexcept {
  static_cast<LiveSession*>(user)->render(nullptr, out, frames);
}

void LiveSession::render(const float* const* inputs, float* const* outputs, int frames) noexcept {
  if (frames < 1 || frames > kMaxCallbackFrames) {
    rejectedCallbacks_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  const int64_t t0 = nowNs();
  const int channels = options_.deviceChannels;
  bool swapped = false;
  // FIFO adapter: each host frame takes the output of the previous engine block at the same
  // position and leaves its input there; a full block is rendered before its output slot is
  // read again, so the delay is exactly one block whatever the call sizes.
  for (int done = 0; done < frames;) {
    const int k = std::min(frames - done, blockSize_ - fill_);
    if (inputs)
      for (size_t s = 0; s < hostIn_.size(); ++s)
        std::copy(inputs[s] + done, inputs[s] + done + k, hostIn_[s].data() + fill_);
    for (int c = 0; c < channels; ++c)
      std::copy(blockOut_[size_t(c)].data() + fill_, blockOut_[size_t(c)].data() + fill_ + k,
                outputs[c] + done);
    fill_ += k;
    done += k;
    if (fill_ == blockSize_) {
      swapped = renderBlock(inputs != nullptr) || swapped;
      fill_ = 0;
    }
  }
  const int64_t t1 = nowNs();
  const int64_t ns = t1 - t0;
  if (double(ns) * 1e-9 * sampleRate_ > double(frames))
    lateCallbacks_.fetch_add(1, std::memory_order_relaxed);
  (swapped ? swapStats_ : noSwapStats_).record(uint64_t(ns), false);
}

bool LiveSession::renderBlock(bool hostInputs) noexcept {
  const int channels = options_.deviceChannels;
  // Newest IR wins; older ones go straight back.
  IrSet* newest = nullptr;
  IrSet* s = nullptr;
  while (toAudio_.try_dequeue(s)) {
    if (newest) {
      fromAudio_.try_enqueue(newest);
      irsDropped_.fetch_add(1, std::memory_order_relaxed);
    }
    newest = s;
  }
  if (newest) audioStage_->offer(newest);
  const uint64_t appliedBefore = audioStage_->irsApplied();
  audioStage_->process(stageOut_.data(), hostInputs ? hostInPtr_.data() : nullptr);
  const bool swapped = audioStage_->irsApplied() != appliedBefore;
  while ((s = audioStage_->takeSpent())) fromAudio_.try_enqueue(s);

  // Device channels: IR channel c (the last one repeats for extra device channels);
  // NaN/inf guard.
  const size_t irChannels = stageOut_.size();
  const size_t B = size_t(blockSize_);
  bool finite = true;
  for (size_t i = 0; i < B * irChannels; ++i) finite = finite && std::isfinite(mono_[i]);
  for (int c = 0; c < channels; ++c) {
    const float* src = stageOut_[std::min(size_t(c), irChannels - 1)];
    float* dst = blockOut_[size_t(c)].data();
    if (finite)
      std::copy(src, src + B, dst);
    else
      std::fill(dst, dst + B, 0.f);
  }
  if (!finite) nanBlocks_.fetch_add(1, std::memory_order_relaxed);
  limiter_->process(blockOutPtr_.data(), channels, B);

  // The recording holds the engine's blocks (what the device plays, without the adapter's
  // leading block of silence).
  if (recordRing_) {
    for (size_t n = 0; n < B; ++n)
      for (int c = 0; c < channels; ++c)
        recordScratch_[n * size_t(channels) + size_t(c)] = blockOut_[size_t(c)][n];
    const size_t want = B * size_t(channels);
    const size_t pushed = recordRing_->push(recordScratch_.data(), want);
    if (pushed < want) recordDropped_.fetch_add(want - pushed, std::memory_order_relaxed);
  }

  const int64_t t1 = nowNs();
  if (const IrSet* cur = audioStage_->current()) {
    irAgeMs_.store(double(t1 - cur->readyNs) * 1e-6, std::memory_order_relaxed);
    if (swapped) latencyStats_.record(uint64_t(std::max<int64_t>(0, t1 - cur->poseNs)), false);
  }
  irsApplied_.store(audioStage_->irsApplied(), std::memory_order_relaxed);
  blocks_.fetch_add(1, std::memory_order_relaxed);
  return swapped;
}

LiveSession::Status LiveSession::status() const {
  Status st;
  st.frames = frames_.load(std::memory_order_relaxed);
  st.frameMs = frameMs_.load(std::memory_order_relaxed);
  const auto now = std::chrono::steady_clock::now();
  const uint64_t rays = rays_.load(std::memory_order_relaxed);
  const double dt = std::chrono::duration<double>(now - lastStatus_).count();
  st.raysPerSecond = dt > 0.0 ? double(rays - lastRays_) / dt : 0.0;
  st.raysPerFrame = raysPerFrame_.load(std::memory_order_relaxed);
  st.raysPerFrameMin = raysPerFrameMin_.load(std::memory_order_relaxed);
  st.raysPerFrameScene = settings_.raysPerFrame;
  st.reducedFrames = reducedFrames_.load(std::memory_order_relaxed);
  lastRays_ = rays;
  lastStatus_ = now;
  st.cacheEntries = cacheEntries_.load(std::memory_order_relaxed);
  st.cacheBytes = cacheBytes_.load(std::memory_order_relaxed);
  st.cacheBudgetBytes = cacheBudgetBytes_.load(std::memory_order_relaxed);
  st.cacheMergedEntries = cacheMergedEntries_.load(std::memory_order_relaxed);
  st.cacheMergedEnergyFraction = cacheMergedEnergyFraction_.load(std::memory_order_relaxed);
  st.irsApplied = irsApplied_.load(std::memory_order_relaxed);
  st.irsDropped = irsDropped_.load(std::memory_order_relaxed);
  st.irAgeMs = irAgeMs_.load(std::memory_order_relaxed);
  const auto lat = latencyStats_.snapshot();
  st.latencyMedianMs = lat.callbacks ? double(lat.quantileNs(0.5)) * 1e-6 : 0.0;
  st.latencyP95Ms = lat.callbacks ? double(lat.quantileNs(0.95)) * 1e-6 : 0.0;
  st.blocks = blocks_.load(std::memory_order_relaxed);
  st.nanBlocks = nanBlocks_.load(std::memory_order_relaxed);
  st.lateCallbacks = lateCallbacks_.load(std::memory_order_relaxed);
  st.rejectedCallbacks = rejectedCallbacks_.load(std::memory_order_relaxed);
  st.recordDropped = recordDropped_.load(std::memory_order_relaxed);
  st.limitedFrames = limiter_->limitedFrames();
  st.overCeilingFrames = limiter_->overCeilingFrames();
  st.limiterMaxReductionDb = limiter_->maxReductionDb();
  return st;
}

audio::AudioData LiveSession::takeRecording() {
  audio::AudioData a;
  a.sampleRate = sampleRate_;
  if (running_.load()) return a;
  const size_t n =
      recorded_.empty()
          ? 0
          : std::min_element(recorded_.begin(), recorded_.end(), [](const auto& x, const auto& y) {
              return x.size() < y.size();
            })->size();
  for (auto& ch : recorded_) {
    ch.resize(n);
    a.channels.push_back(std::move(ch));
  }
  recorded_.clear();
  return a;
}

NullOutput::NullOutput(int sampleRate, int blockSize, int channels, audio::RenderCallback cb,
                       void* user)
    : sampleRate_(sampleRate),
      blockSize_(blockSize),
      channels_(channels),
      callback_(cb),
      user_(user) {
  buffers_.assign(size_t(channels), std::vector<float>(size_t(blockSize)));
  for (auto& b : buffers_) pointers_.push_back(b.data());
}

NullOutput::~NullOutput() {
  stop();
}

void NullOutput::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] {
    const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(double(blockSize_) / sampleRate_));
    auto next = std::chrono::steady_clock::now();
    while (running_.load(std::memory_order_relaxed)) {
      const auto t0 = std::chrono::steady_clock::now();
      callback_(user_, pointers_.data(), blockSize_);
      const auto t1 = std::chrono::steady_clock::now();
      next += period;
      const bool late = t1 > next;  // the callback overran its block period
      stats_.record(uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count()),
                    late);
      if (late)
        next = t1;
      else
        std::this_thread::sleep_until(next);
    }
  });
}

void NullOutput::stop() {
  if (!running_.exchange(false)) return;
  if (thread_.joinable()) thread_.join();
}

}  // namespace dpc
