#include "runtime/propagation_stage.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>

#include "engine/room_volume.h"
#include "runtime/output_format.h"
#include "scene/orientation.h"
#include "scene/trajectory.h"

namespace dpc {

namespace {
double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

PropagationStage::PropagationStage(std::shared_ptr<const SceneDesc> scene,
                                   const PropagationSettings& settings, int poolSize,
                                   audio::ConvolverLayout::Planning planning)
    : scene_(std::move(scene)),
      numOutputs_(irChannels(scene_->audio)),
      channelScratch_(size_t(numOutputs_)) {
  simulation_ = std::make_unique<Simulation>(*scene_, settings);
  const double early = hybridEarlySeconds(settings);
  makeSynthesizers(settings, early > 0.0);
  if (early > 0.0) makeHybrid(settings, early, planning);
  layout_ = std::make_shared<const audio::NonUniformLayout>(
      scene_->audio.blockSize, irSamples_, audio::NonUniformLayout::kDefaultMaxPartition, planning);
  makePool(poolSize);
  const auto channels = [&](size_t n, size_t samples) {
    return std::vector<std::vector<std::vector<float>>>(
        n, std::vector<std::vector<float>>(size_t(numOutputs_), std::vector<float>(samples)));
  };
  irs_.assign(1, channels(scene_->sources.size(), irSamples_));
  if (hybrid_) lateIrs_.assign(1, channels(size_t(hybrid_->buses()), lateLayout_->maxIrSamples()));
}

double PropagationStage::hybridEarlySeconds(const PropagationSettings& settings) const {
  const SceneDesc& scene = *scene_;
  if (!rendersHybrid(scene.audio, scene.sources.size())) return 0.0;
  const Geometry& g = simulation_->geometry();
  const double early =
      hybridEarlyLength(double(glm::length(g.boundsMax() - g.boundsMin())), settings.speedOfSound,
                        settings.irLength, kHybridFadeSeconds);
  return early < double(settings.irLength) ? early : 0.0;  // else the early part is the whole IR
}

void PropagationStage::makeHybrid(const PropagationSettings& settings, double early,
                                  audio::ConvolverLayout::Planning planning) {
  const SceneDesc& scene = *scene_;
  hybrid_ = std::make_unique<HybridSynthesis>(
      scene, settings, roomVolume(scene.mesh), spatial_.get(), early, scene.listeners.size(),
      simulation_->propagator().concurrency(), onTracingThreads());
  if (hybrid_->earlySpatial()) levelOnTracingThreads(*hybrid_->earlySpatial());
  lateLayout_ = std::make_shared<const audio::NonUniformLayout>(
      scene.audio.blockSize, hybrid_->lateSamples(), audio::NonUniformLayout::kDefaultMaxPartition,
      planning);
  irSamples_ = hybrid_->earlySamples();
}

void PropagationStage::makeSynthesizers(const PropagationSettings& settings, bool hybrid) {
  const SceneDesc& scene = *scene_;
  const int fs = scene.audio.sampleRate;
  if (scene.audio.output == OutputFormat::kMono) {
    if (hybrid) return;  // the hybrid synthesis has its own early and late synthesisers
    for (size_t s = 0; s < scene.sources.size(); ++s)
      synthesizers_.push_back(std::make_unique<IrSynthesizer>(
          fs, settings.irLength, roomVolume(scene.mesh), settings.speedOfSound,
          hashCombine(settings.seed, 0x5bd1e995ULL + s),
          synthesizers_.empty() ? nullptr : synthesizers_.front().get()));
    irSamples_ = synthesizers_.front()->lengthSamples();
  } else {
    spatial_ = makeSpatialSynthesizer(scene, settings, roomVolume(scene.mesh));
    levelOnTracingThreads(*spatial_);
    simulation_->enableDirectional(spatial_->directions());
    irSamples_ = spatial_->lengthSamples();
  }
}

SpatialIrSynthesizer::ParallelFor PropagationStage::onTracingThreads() {
  // The synthesis runs between frames, when the tracing threads are idle.
  Propagator& p = simulation_->propagator();
  return [&p](size_t n, const std::function<void(size_t)>& f) { p.forEachParallel(n, f); };
}

void PropagationStage::levelOnTracingThreads(SpatialIrSynthesizer& synth) {
  synth.setParallelLevelling(simulation_->propagator().concurrency(), onTracingThreads());
}

void PropagationStage::makePool(int poolSize) {
  const int sets = poolSize + 2 * (layout_->numLevels() - 1);
  for (int i = 0; i < sets; ++i) {
    auto set = std::make_unique<IrSet>();
    set->irs = std::make_unique<audio::NonUniformIrSet>(*layout_, int(scene_->sources.size()),
                                                        numOutputs_);
    if (hybrid_) {
      set->lateIrs =
          std::make_unique<audio::NonUniformIrSet>(*lateLayout_, hybrid_->buses(), numOutputs_);
      set->lateGain.assign(scene_->sources.size(), 0.f);
      set->lateBus.assign(scene_->sources.size(), 0);
    }
    free_.push_back(set.get());
    pool_.push_back(std::move(set));
  }
}

void PropagationStage::traceWorld(const WorldState& world) {
  const SceneDesc& scene = *scene_;
  const size_t L = world.listenerPositions.size();
  if (L == 0 || world.listenerOrientations.size() != L ||
      world.sourcePositions.size() != scene.sources.size() ||
      world.objectPoses.size() != scene.objects.size())
    throw std::invalid_argument(
        "PropagationStage::traceWorld: the world state does not match "
        "the scene's sources and objects, or has no listener");
  spheres_.resize(L);
  for (size_t l = 0; l < L; ++l) {
    const float radius = scene.listeners[l % scene.listeners.size()].radius;
    spheres_[l] = ListenerSphere{world.listenerPositions[l], radius};
    // Head-tracked binaural: IRs in the reference head frame (yaw 0, pitch 0); the audio
    // stage turns them by the listener's orientation per block.
    simulation_->setListenerOrientation(l, scene.audio.output == OutputFormat::kAmbisonicBinaural
                                               ? Orientation{}
                                               : world.listenerOrientations[l]);
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (!world.objectPoses.empty()) simulation_->setObjectPoses(world.objectPoses);
  if (!world.sourceRotations.empty()) simulation_->setSourceRotations(world.sourceRotations);
  for (size_t s = 0; s < world.sourceTeleports.size(); ++s)
    if (world.sourceTeleports[s]) simulation_->restartSource(s);
  for (size_t l = 0; l < world.listenerTeleports.size() && l < L; ++l)
    if (world.listenerTeleports[l]) simulation_->restartListener(l);
  // Pairs played from the bake are not traced (Simulation::setSkippedPairs).
  if (baked_) baked_->beginFrame(world.sourcePositions, spheres_);
  simulation_->setSkippedPairs(baked_ ? std::span<const uint8_t>(baked_->bakedPairs())
                                      : std::span<const uint8_t>());
  simulation_->runFrame(spheres_, world.sourcePositions);
  sources_ = world.sourcePositions;
  totals_.traceSeconds += secondsSince(t0);
  totals_.rays += simulation_->frameTrace().rays;
  totals_.segments += simulation_->frameTrace().segments;
  while (irs_.size() < L) irs_.push_back(irs_.front());
  while (lateIrs_.size() < L && !lateIrs_.empty()) lateIrs_.push_back(lateIrs_.front());
  lastTime_ = world.timeSeconds;
  ++totals_.frames;
}

void PropagationStage::synthesize(size_t s, size_t listener) {
  auto& irs = irs_[listener];
  const Simulation::SourceResult& r = simulation_->result(s, listener);
  if (spatial_) {
    for (size_t c = 0; c < channelScratch_.size(); ++c) channelScratch_[c] = irs[s][c].data();
    const DirectionalEnergyResponse& live = simulation_->directional(s, listener);
    spatial_->synthesize(baked_ ? baked_->directional(s, listener, live) : live, r.direct,
                         channelScratch_, simulation_->specularPaths(s, listener));
  } else {
    synthesizers_[s]->synthesize(baked_ ? baked_->energy(s, listener, r.energy) : r.energy,
                                 r.direct, irs[s][0].data(),
                                 simulation_->specularPaths(s, listener));
  }
}

IrSet* PropagationStage::prepare(size_t listener) {
  if (listener >= simulation_->listenerCount())
    throw std::out_of_range("PropagationStage::prepare: listener index out of range");
  if (free_.empty()) return nullptr;
  IrSet* set = free_.back();
  free_.pop_back();
  if (hybrid_) prepareLate(listener, *set);
  for (size_t s = 0; s < simulation_->sourceCount(); ++s) {
    auto t0 = std::chrono::steady_clock::now();
    if (!hybrid_) synthesize(s, listener);
    totals_.synthesisSeconds += secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    for (int c = 0; c < numOutputs_; ++c)
      channelScratch_[size_t(c)] = irs_[listener][s][size_t(c)].data();
    set->irs->prepare(int(s), channelScratch_.data(), irSamples_);
    totals_.prepareSeconds += secondsSince(t0);
  }
  set->listener = listener;
  set->frame = simulation_->framesRun() - 1;
  set->poseTimeSeconds = lastTime_;
  return set;
}

void PropagationStage::prepareLate(size_t listener, IrSet& set) {
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::vector<std::vector<float>>>& late = lateIrs_[listener];
  hybrid_->prepare(*simulation_, listener, spheres_[listener].position, sources_, baked_.get(),
                   irs_[listener], late, set.lateGain, set.lateBus);
  totals_.synthesisSeconds += secondsSince(t0);
  t0 = std::chrono::steady_clock::now();
  for (size_t k = 0; k < late.size(); ++k) {
    for (int c = 0; c < numOutputs_; ++c) channelScratch_[size_t(c)] = late[k][size_t(c)].data();
    set.lateIrs->prepare(int(k), channelScratch_.data(), lateLayout_->maxIrSamples());
  }
  totals_.prepareSeconds += secondsSince(t0);
  if (lastGain_.size() <= listener) lastGain_.resize(listener + 1), lastBus_.resize(listener + 1);
  lastGain_[listener].assign(set.lateGain.begin(), set.lateGain.end());
  lastBus_[listener].assign(set.lateBus.begin(), set.lateBus.end());
}

std::vector<std::vector<std::vector<float>>> PropagationStage::wholeIrs(size_t listener) const {
  std::vector<std::vector<std::vector<float>>> out;
  wholeIrsInto(listener, out);
  return out;
}

void PropagationStage::wholeIrsInto(size_t listener,
                                    std::vector<std::vector<std::vector<float>>>& out) const {
  const auto& early = irs_.at(listener);
  if (!hybrid_ || listener >= lastGain_.size()) {
    out = early;  // element-wise assignment: the inner vectors keep their capacity
    return;
  }
  const auto& late = lateIrs_.at(listener);
  out.resize(early.size());
  for (size_t s = 0; s < early.size(); ++s) {
    const auto& bus = late[size_t(lastBus_[listener][s])];
    const float g = lastGain_[listener][s];
    out[s].resize(early[s].size());
    for (size_t c = 0; c < early[s].size(); ++c) {
      std::vector<float>& x = out[s][c];
      x.resize(bus[c].size());
      for (size_t n = 0; n < x.size(); ++n) x[n] = g * bus[c][n];
      for (size_t n = 0; n < early[s][c].size() && n < x.size(); ++n) x[n] += early[s][c][n];
    }
  }
}

void PropagationStage::attachBake(std::shared_ptr<const BakedField> bake,
                                  BakeInterpolation settings) {
  baked_ =
      bake ? std::make_unique<BakedPlayback>(std::move(bake), *simulation_, settings) : nullptr;
}

void PropagationStage::recycle(IrSet* set) {
  assert(set == nullptr || std::find(free_.begin(), free_.end(), set) == free_.end());
  if (set) free_.push_back(set);
}

}  // namespace dpc
