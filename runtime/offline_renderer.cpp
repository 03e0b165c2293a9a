#include "runtime/offline_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "audio/rt_check.h"
#include "engine/specular_paths.h"
#include "runtime/output_format.h"
#include "runtime/session_stats.h"
#include "scene/trajectory.h"
#include "wave/scene_wave.h"

namespace dpc {

namespace {

/// Scene listener indices rendered, in OfflineResult::listeners order.
std::vector<size_t> renderedListeners(const SceneDesc& scene, const OfflineOptions& options) {
  if (options.allListeners) {
    std::vector<size_t> all(scene.listeners.size());
    for (size_t l = 0; l < all.size(); ++l) all[l] = l;
    return all;
  }
  if (options.listener >= scene.listeners.size())
    throw std::out_of_range("renderOffline: listener " + std::to_string(options.listener) +
                            " is not one of the scene's " + std::to_string(scene.listeners.size()) +
                            " listeners");
  return {options.listener};
}

/// One offline render: the pipeline, the simulated clock and the outputs.
class OfflineRender {
 public:
  OfflineRender(std::shared_ptr<const SceneDesc> scene, const PropagationSettings& settings,
                std::shared_ptr<const DrySignals> dry, const OfflineOptions& options);
  OfflineResult run();

 private:
  /// Runs the propagation frames due by scene time t, publishing each rendered listener's IR
  /// set to its channel of the exchange (newest wins).
  void runFramesDue(double t);
  /// Renders block blk of every rendered listener.
  void renderBlock(size_t blk);
  /// Totals, last responses and outputs cut to length.
  void finish();

  std::shared_ptr<const SceneDesc> scene_;
  const OfflineOptions& options_;
  std::vector<size_t> listeners_;
  PropagationStage propagation_;
  std::unique_ptr<IrExchange> exchange_;  ///< one channel per rendered listener
  std::vector<std::unique_ptr<AudioStage>> audioStages_;
  size_t B_, totalFrames_, blocks_;
  bool streaming_;
  double framePeriod_;
  uint64_t nextFrame_ = 0;
  WorldState world_;
  std::vector<float*> out_;
  OfflineResult result_;
};

OfflineRender::OfflineRender(std::shared_ptr<const SceneDesc> scene,
                             const PropagationSettings& settings,
                             std::shared_ptr<const DrySignals> dry, const OfflineOptions& options)
    : scene_(std::move(scene)),
      options_(options),
      listeners_(renderedListeners(*scene_, options)),
      propagation_(scene_, settings),
      // Each audio stage holds at most its current set and one in its mailbox; one more is
      // being filled.
      exchange_(propagation_.makeExchange(listeners_.size(),
                                          int(std::max<size_t>(4, 3 * listeners_.size() + 1)))),
      B_(size_t(scene_->audio.blockSize)),
      streaming_(bool(options.sink)),
      framePeriod_(1.0 / settings.frameRate) {
  if (options.bake) propagation_.attachBake(options.bake);
  // A bake that carries the wave band plays it (PropagationStage::attachBake): nothing to
  // simulate.
  if (scene_->wave.enabled && !(options.bake && options.bake->hasWave())) {
    propagation_.checkWaveBandsAllowed();  // before minutes of simulation, not after
    propagation_.attachWaveBands(
        wave::sceneWaveBands(*scene_, listeners_, settings.irLength, options.waveProgress));
  }
  for (size_t k = 0; k < listeners_.size(); ++k) {
    audioStages_.push_back(std::make_unique<AudioStage>(propagation_, dry, *exchange_, k));
    audioStages_.back()->setSkipSilentLevels(false);  // exact: no time limit per block offline
  }
  const int fs = scene_->audio.sampleRate;
  totalFrames_ = size_t(std::ceil(offlineDurationSeconds(*scene_, settings, *dry, options) * fs));
  blocks_ = (totalFrames_ + B_ - 1) / B_;
  result_.listeners.resize(listeners_.size());
  for (size_t k = 0; k < listeners_.size(); ++k) {
    OfflineListenerResult& lr = result_.listeners[k];
    lr.name = scene_->listeners[listeners_[k]].name;
    lr.output.sampleRate = fs;
    // Streaming: one block per channel, handed to the sink; otherwise the whole render is kept.
    lr.output.channels.assign(size_t(renderedChannels(scene_->audio)),
                              std::vector<float>(streaming_ ? B_ : blocks_ * B_));
  }
  out_.resize(size_t(renderedChannels(scene_->audio)));
}

void OfflineRender::runFramesDue(double t) {
  while (double(nextFrame_) * framePeriod_ <= t + 1e-12) {
    evaluateWorld(*scene_, double(nextFrame_) * framePeriod_, world_);
    propagation_.traceWorld(world_);
    for (size_t k = 0; k < listeners_.size(); ++k) {
      IrSet* set = exchange_->acquire();
      if (!set) {
        ++result_.irsLost;
        continue;
      }
      propagation_.prepare(listeners_[k], *set);
      exchange_->publish(k, set);
    }
    ++nextFrame_;
  }
}

void OfflineRender::renderBlock(size_t blk) {
  // The render loop plays the audio thread for the stages (audio/rt_check.h).
  const audio::rt::ScopedThreadRole role(audio::rt::ThreadRole::kAudio);
  for (size_t k = 0; k < listeners_.size(); ++k) {
    // Head-tracked binaural: the head's orientation at this block's time (audio rate).
    audioStages_[k]->setHeadOrientation(listenerOrientationAt(
        scene_->listeners[listeners_[k]], double(blk * B_) / scene_->audio.sampleRate));
    for (size_t c = 0; c < out_.size(); ++c)
      out_[c] = result_.listeners[k].output.channels[c].data() + (streaming_ ? 0 : blk * B_);
    audioStages_[k]->process(out_.data());
    if (streaming_) options_.sink(k, out_.data(), std::min(B_, totalFrames_ - blk * B_));
  }
}

OfflineResult OfflineRender::run() {
  const auto wall0 = std::chrono::steady_clock::now();
  const double fs = scene_->audio.sampleRate;
  size_t lastReport = 0;
  for (size_t blk = 0; blk < blocks_; ++blk) {
    runFramesDue(double(blk * B_) / fs);  // normally at most one frame
    renderBlock(blk);
    if (options_.progress && (blk + 1 == blocks_ || (blk - lastReport) * 100 >= blocks_)) {
      options_.progress(double((blk + 1) * B_) / fs, double(blocks_ * B_) / fs);
      lastReport = blk;
    }
  }
  finish();
  result_.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return std::move(result_);
}

void OfflineRender::finish() {
  result_.totals = propagation_.totals();
  const BakedPlayback* baked = propagation_.bakedPlayback();
  if (baked) result_.bake = baked->stats();
  if (propagation_.hybrid()) result_.hybrid = propagation_.hybrid()->report(listeners_.front());
  const Simulation& sim = propagation_.simulation();
  FrameTotals totals;
  for (size_t k = 0; k < listeners_.size(); ++k) {
    OfflineListenerResult& lr = result_.listeners[k];
    if (streaming_)
      lr.output.channels.clear();
    else
      for (auto& ch : lr.output.channels) ch.resize(totalFrames_);
    lr.lastIrs = propagation_.wholeIrs(listeners_[k]);
    lr.lastListenerPosition = world_.listenerPositions[listeners_[k]];
    lr.lastListenerOrientation = world_.listenerOrientations[listeners_[k]];
    lr.lastSourcePositions = world_.sourcePositions;
    lr.irsApplied = audioStages_[k]->irsApplied();
    result_.stalePartitions += audioStages_[k]->stalePartitions();
    for (size_t s = 0; s < sim.sourceCount(); ++s) {
      const Simulation::SourceResult& sr = sim.result(s, listeners_[k]);
      totals.add(sr);
      // The whole response: the exact early paths, kept out of the estimators' response, are
      // added at their delays. A pair played from a bake is not traced (sr.energy is empty):
      // its response is the bake's late response interpolated at the listener, as synthesised.
      lr.lastEnergy.push_back(sr.energy);
      if (baked && baked->plays(s, listeners_[k]))
        baked->interpolate(s, listeners_[k], lr.lastEnergy.back());
      addSpecularPaths(sim.specularPaths(s, listeners_[k]), lr.lastEnergy.back());
      lr.lastDirect.push_back(sr.direct);
    }
  }
  result_.last = totals;
}

}  // namespace

double offlineDurationSeconds(const SceneDesc& scene, const PropagationSettings& settings,
                              const DrySignals& dry, const OfflineOptions& options) {
  if (options.durationSeconds >= 0.0) return options.durationSeconds;
  double content = double(dry.longestFrames()) / scene.audio.sampleRate;
  for (size_t l : renderedListeners(scene, options)) {
    const ListenerDesc& d = scene.listeners[l];
    if (!d.loop && !d.trajectory.empty())
      content = std::max(content, d.trajectory.back().timeSeconds);
  }
  for (const SourceDesc& s : scene.sources)
    if (!s.trajectoryLoop && !s.trajectory.empty())
      content = std::max(content, s.trajectory.back().timeSeconds);
  return content + settings.irLength;
}

OfflineResult renderOffline(std::shared_ptr<const SceneDesc> scene,
                            const PropagationSettings& settings,
                            std::shared_ptr<const DrySignals> dry, const OfflineOptions& options) {
  return OfflineRender(std::move(scene), settings, std::move(dry), options).run();
}

}  // namespace dpc
