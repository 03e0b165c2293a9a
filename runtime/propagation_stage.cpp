#include "runtime/propagation_stage.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <functional>
#include <glm/geometric.hpp>
#include <stdexcept>

#include "common/input_error.h"
#include "common/stopwatch.h"
#include "engine/room_volume.h"
#include "runtime/output_format.h"
#include "runtime/own_threads.h"
#include "scene/orientation.h"
#include "scene/trajectory.h"

namespace dpc {

PropagationStage::PropagationStage(std::shared_ptr<const SceneDesc> scene,
                                   const PropagationSettings& settings,
                                   audio::ConvolverLayout::Planning planning,
                                   IrSynthesizer::Build build)
    : scene_(std::move(scene)),
      numOutputs_(irChannels(scene_->audio)) {
  simulation_ = std::make_unique<Simulation>(*scene_, settings);
  sourceGroups_ = std::clamp<size_t>(size_t(std::max(1, simulation_->propagator().concurrency())),
                                     1, std::max<size_t>(1, scene_->sources.size()));
  channelScratch_.assign(sourceGroups_, std::vector<float*>(size_t(numOutputs_)));
  partitionChannels_.assign(size_t(std::max(1, simulation_->propagator().concurrency())),
                            std::vector<const float*>(size_t(numOutputs_)));
  const double early = hybridEarlySeconds(settings);
  makeSynthesizers(settings, early > 0.0, build);
  if (early > 0.0) makeHybrid(settings, early, planning, build);
  layout_ = std::make_shared<const audio::NonUniformLayout>(
      scene_->audio.blockSize, irSamples_, audio::NonUniformLayout::kDefaultMaxPartition, planning);
  const auto responses = [&](size_t n, size_t samples) {
    std::vector<ImpulseResponse> irs(
        n, ImpulseResponse(numOutputs_, samples, double(scene_->audio.sampleRate)));
    for (size_t i = 0; i < n; ++i) irs[i].source = i;
    return irs;
  };
  irs_.assign(1, responses(scene_->sources.size(), irSamples_));
  if (hybrid_)
    lateIrs_.assign(1, responses(size_t(hybrid_->buses()), lateLayout_->maxIrSamples()));
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
                                  audio::ConvolverLayout::Planning planning,
                                  IrSynthesizer::Build build) {
  const SceneDesc& scene = *scene_;
  hybrid_ = std::make_unique<HybridSynthesis>(
      scene, settings, roomVolume(scene.mesh), spatial_.get(), early, scene.listeners.size(),
      simulation_->propagator().concurrency(), onTracingThreads(), build);
  lateLayout_ = std::make_shared<const audio::NonUniformLayout>(
      scene.audio.blockSize, hybrid_->lateSamples(), audio::NonUniformLayout::kDefaultMaxPartition,
      planning);
  irSamples_ = hybrid_->earlySamples();
}

void PropagationStage::makeSynthesizers(const PropagationSettings& settings, bool hybrid,
                                        IrSynthesizer::Build build) {
  const SceneDesc& scene = *scene_;
  const int fs = scene.audio.sampleRate;
  if (scene.audio.output == OutputFormat::kMono) {
    if (hybrid) return;  // the hybrid synthesis has its own early and late synthesisers
    // Per source its own Dirac sequence; source s shares the workspace of group s % G's first.
    // The groups are built concurrently (the time to first sound).
    const size_t S = scene.sources.size(), G = sourceGroups_;
    const double volume = roomVolume(scene.mesh);
    synthesizers_.resize(S);
    onOwnThreads(G, [&](size_t g) {
      for (size_t s = g; s < S; s += G)
        synthesizers_[s] = std::make_unique<IrSynthesizer>(
            fs, settings.irLength, volume, settings.speedOfSound,
            hashCombine(settings.seed, 0x5bd1e995ULL + s),
            s < G ? nullptr : synthesizers_[g].get(), build);
    });
    irSamples_ = synthesizers_.front()->lengthSamples();
  } else {
    spatial_ = makeSpatialSynthesizer(scene, settings, roomVolume(scene.mesh));
    levelOnTracingThreads(*spatial_);
    if (!hybrid)
      while (spatialCopies_.size() + 1 < sourceGroups_)
        spatialCopies_.push_back(spatial_->workspaceCopy());
    simulation_->enableDirectional(spatial_->directions());
    irSamples_ = spatial_->lengthSamples();
  }
}

bool PropagationStage::synthesisCompleted() const {
  for (const auto& synth : synthesizers_)
    if (!synth->completed()) return false;
  return !hybrid_ || hybrid_->completed();
}

void PropagationStage::completeSynthesis() {
  if (!synthesizers_.empty() && !synthesizers_.back()->completed()) {
    // The groups' first synthesisers (each its own window leveller) first, then their
    // sharers' own parts (they touch nothing shared) on the tracing threads.
    const size_t G = std::min(sourceGroups_, synthesizers_.size());
    Propagator& p = simulation_->propagator();
    p.forEachParallel(G, [&](size_t g) { synthesizers_[g]->complete(); });
    p.forEachParallel(synthesizers_.size() - G, [&](size_t i) {
      synthesizers_[G + i]->complete(synthesizers_[(G + i) % G].get());
    });
    whole_.forget();  // the IRs after completion are not those made before
  }
  if (hybrid_) hybrid_->complete();
}

void PropagationStage::reuseSourceIrs(double toleranceDb) {
  whole_.setTolerance(toleranceDb);
  if (hybrid_) hybrid_->reuseEarlyParts(toleranceDb);
}

bool PropagationStage::fftPlansMeasured() const {
  return layout_->plansMeasured() && (!lateLayout_ || lateLayout_->plansMeasured());
}

void PropagationStage::measureFftPlans() const {
  layout_->measurePlans();
  if (lateLayout_) lateLayout_->measurePlans();
}

SpatialIrSynthesizer::ParallelFor PropagationStage::onTracingThreads() {
  // The synthesis runs between frames, when the tracing threads are idle.
  Propagator& p = simulation_->propagator();
  return [&p](size_t n, const std::function<void(size_t)>& f) { p.forEachParallel(n, f); };
}

void PropagationStage::levelOnTracingThreads(SpatialIrSynthesizer& synth) {
  synth.setParallelLevelling(simulation_->propagator().concurrency(), onTracingThreads());
}

std::unique_ptr<IrSet> PropagationStage::makeIrSet() const {
  auto set = std::make_unique<IrSet>();
  set->irIds.assign(scene_->sources.size(), 0);
  set->irs =
      std::make_unique<audio::NonUniformIrSet>(*layout_, int(scene_->sources.size()), numOutputs_,
                                               int(partitionChannels_.size()));
  if (hybrid_) {
    set->lateIrs =
        std::make_unique<audio::NonUniformIrSet>(*lateLayout_, hybrid_->buses(), numOutputs_,
                                                 int(partitionChannels_.size()));
    set->lateGain.assign(scene_->sources.size(), 0.f);
    set->lateBus.assign(scene_->sources.size(), 0);
    set->lateIrIds.assign(size_t(hybrid_->buses()), 0);
  }
  return set;
}

std::unique_ptr<IrExchange> PropagationStage::makeExchange(size_t channels, int baseSets) const {
  const int sets = baseSets + 2 * (layout_->numLevels() - 1);
  return std::make_unique<IrExchange>(channels, size_t(std::max(1, sets)),
                                      [this] { return makeIrSet(); });
}

void PropagationStage::traceWorld(const WorldState& world, int raysPerEmitter) {
  const SceneDesc& scene = *scene_;
  const size_t L = world.listenerPositions.size();
  if (L == 0 || world.listenerOrientations.size() != L ||
      world.sourcePositions.size() != scene.sources.size() ||
      world.objectPoses.size() != scene.objects.size())
    throw std::invalid_argument(
        "PropagationStage::traceWorld: the world state does not match "
        "the scene's sources and objects, or has no listener");
  frameInputs(world, raysPerEmitter);
  simulation_->runFrame(inputs_);
  sources_ = world.sourcePositions;
  recordFrameTimes(simulation_->frameTimes());
  totals_.rays += simulation_->frameTrace().rays;
  totals_.segments += simulation_->frameTrace().segments;
  while (irs_.size() < L) irs_.push_back(irs_.front());
  while (lateIrs_.size() < L && !lateIrs_.empty()) lateIrs_.push_back(lateIrs_.front());
  lastTime_ = world.timeSeconds;
  ++totals_.frames;
}

void PropagationStage::recordFrameTimes(const Simulation::FrameTimes& t) {
  totals_.traceSeconds += t.trace;
  totals_.pairsSeconds += t.pairs + t.pool;
  profile_->record(FrameProfile::kTrace, t.trace);
  profile_->record(FrameProfile::kPairs, t.pairs + t.pool);
  profile_->recordPairCpu(t.directCpu, t.exactCpu, t.estimatorCpu);
}

void PropagationStage::frameInputs(const WorldState& world, int raysPerEmitter) {
  const SceneDesc& scene = *scene_;
  const size_t L = world.listenerPositions.size();
  inputs_.listeners.resize(L);
  inputs_.listenerOrientations.resize(L);
  for (size_t l = 0; l < L; ++l) {
    const float radius = scene.listeners[l % scene.listeners.size()].radius;
    inputs_.listeners[l] = ListenerSphere{world.listenerPositions[l], radius};
    // Head-tracked binaural: IRs in the reference head frame (yaw 0, pitch 0); the audio
    // stage turns them by the listener's orientation per block.
    inputs_.listenerOrientations[l] = scene.audio.output == OutputFormat::kAmbisonicBinaural
                                          ? Orientation{}
                                          : world.listenerOrientations[l];
  }
  inputs_.sourcePositions = world.sourcePositions;
  inputs_.sourceRotations = world.sourceRotations;
  inputs_.objectPoses = world.objectPoses;
  inputs_.sourceRestarts = world.sourceTeleports;
  inputs_.listenerRestarts = world.listenerTeleports;
  // Pairs played from the bake are not traced.
  if (baked_) baked_->beginFrame(world.sourcePositions, inputs_.listeners);
  if (baked_)
    inputs_.skippedPairs.assign(baked_->bakedPairs().begin(), baked_->bakedPairs().end());
  else
    inputs_.skippedPairs.clear();
  inputs_.raysPerEmitter = raysPerEmitter;
}

void PropagationStage::synthesize(size_t s, size_t listener, size_t g) {
  ImpulseResponse& ir = irs_[listener][s];
  const Simulation::SourceResult& r = simulation_->result(s, listener);
  const std::vector<SpecularPath>& paths = simulation_->specularPaths(s, listener);
  // Joined wave bands blend with the listener's probes: not among the inputs compared.
  const bool keepable = !waveBands_ && !bakedWave_;
  if (spatial_) {
    const DirectionalEnergyResponse& live = simulation_->directional(s, listener);
    const DirectionalEnergyResponse& in = baked_ ? baked_->directional(s, listener, live) : live;
    if (keepable && whole_.kept(in, r.direct, paths, &in.frame(), listener, s, g)) return;
    std::vector<float*>& channels = channelScratch_[g];
    for (size_t c = 0; c < channels.size(); ++c) channels[c] = ir.channel(int(c));
    SpatialIrSynthesizer& synth = g == 0 ? *spatial_ : *spatialCopies_[g - 1];
    synth.synthesize(in, r.direct, channels, paths, s);
  } else {
    const EnergyResponse& in = baked_ ? baked_->energy(s, listener, r.energy) : r.energy;
    if (keepable && whole_.kept(in, r.direct, paths, nullptr, listener, s, g)) return;
    synthesizers_[s]->synthesize(in, r.direct, ir.channel(0), paths);
  }
  joinWave(s, listener, ir);
  whole_.made(listener, s, g);
}

void PropagationStage::joinWave(size_t s, size_t listener, ImpulseResponse& ir) {
  if (bakedWave_ && baked_->plays(s, listener)) {
    // The late response's probes and weights, over the probes whose air the source reached.
    waveBlend_.clear();
    float total = 0.f;
    for (const ProbeWeight& w : baked_->interpolator(listener).weights())
      if (bakedWave_->has(w.probe, s)) {
        waveBlend_.push_back({w.probe, w.weight});
        total += w.weight;
      }
    if (total <= 0.f) return;  // no probe of the blend in the source's air: no wave band
    for (wave::BandWeight& b : waveBlend_) b.weight /= total;
    bakedWave_->join(waveBlend_, s, ir);
    return;
  }
  if (waveBands_ && waveBands_->has(listener, s)) waveBands_->join(listener, s, ir);
}

void PropagationStage::checkWaveBandsAllowed() const {
  if (hybrid_)
    throw InputError(scene_->path, "wave.enabled",
                     "the wave band needs each source's whole IR: set audio.rendering to "
                     "\"per_source\" (this scene renders hybrid)");
}

void PropagationStage::attachWaveBands(std::shared_ptr<const wave::WaveBandSet> bands) {
  if (bands) checkWaveBandsAllowed();
  waveBands_ = std::move(bands);
}

void PropagationStage::synthesizeSources(size_t listener) {
  const size_t S = simulation_->sourceCount();
  const size_t G = baked_ || waveBands_ ? 1 : sourceGroups_;
  whole_.ensure(listener + 1, S, G);  // allocates on a listener's first frame only
  const auto group = [&](size_t g) {
    for (size_t s = g; s < S; s += G) synthesize(s, listener, g);
  };
  // By reference: a std::function holding the lambda itself would allocate every frame.
  simulation_->propagator().forEachParallel(G, std::ref(group));
  whole_.drainCounts(listener);
}

void PropagationStage::synthesizeIrs(size_t listener) {
  if (listener >= simulation_->listenerCount())
    throw std::out_of_range("PropagationStage: listener index out of range");
  const auto t0 = std::chrono::steady_clock::now();
  const uint64_t frame = simulation_->framesRun() - 1;
  if (hybrid_)
    synthesizeHybrid(listener);
  else
    synthesizeSources(listener);
  for (size_t s = 0; s < simulation_->sourceCount(); ++s) irs_[listener][s].frame = frame;
  if (hybrid_)
    for (ImpulseResponse& late : lateIrs_[listener]) late.frame = frame;
  totals_.synthesisSeconds += secondsSince(t0);
}

void PropagationStage::prepare(size_t listener, IrSet& set) {
  const double synthesized = totals_.synthesisSeconds;
  synthesizeIrs(listener);
  profile_->record(FrameProfile::kSynthesis, totals_.synthesisSeconds - synthesized);
  const auto t0 = std::chrono::steady_clock::now();
  partition(listener, set);
  if (hybrid_) {
    set.lateGain.assign(lastGain_[listener].begin(), lastGain_[listener].end());
    set.lateBus.assign(lastBus_[listener].begin(), lastBus_[listener].end());
  }
  const double partitioned = secondsSince(t0);
  totals_.prepareSeconds += partitioned;
  profile_->record(FrameProfile::kPartition, partitioned);
  set.listener = listener;
  set.frame = simulation_->framesRun() - 1;
  set.poseTimeSeconds = lastTime_;
}

void PropagationStage::partition(size_t listener, IrSet& set) {
  // Items: the sources' IRs, then the buses'; group g takes items g, g + G, ...
  std::vector<ImpulseResponse>& irs = irs_[listener];
  const size_t S = irs.size(), B = hybrid_ ? lateIrs_[listener].size() : 0;
  int groups = std::min(set.irs->workers(), int(partitionChannels_.size()));
  if (hybrid_) groups = std::min(groups, set.lateIrs->workers());
  const size_t G = size_t(std::max(groups, 1));
  const auto group = [&](size_t g) {
    std::vector<const float*>& channels = partitionChannels_[g];
    for (size_t i = g; i < S + B; i += G) {
      const bool early = i < S;
      const ImpulseResponse& ir = early ? irs[i] : lateIrs_[listener][i - S];
      // An IR kept since this set last partitioned it is in the set already.
      const uint64_t id =
          early ? sourceIrId(listener, i) : hybrid_->busIrId(listener, int(i - S));
      uint64_t& held = early ? set.irIds[i] : set.lateIrIds[i - S];
      if (id != 0 && held == id) continue;
      for (int c = 0; c < numOutputs_; ++c) channels[size_t(c)] = ir.channel(c);
      if (early)
        set.irs->prepare(int(i), channels.data(), irSamples_, int(g));
      else
        set.lateIrs->prepare(int(i - S), channels.data(), lateLayout_->maxIrSamples(), int(g));
      held = id;
    }
  };
  simulation_->propagator().forEachParallel(G, std::ref(group));  // no allocation
}

void PropagationStage::synthesizeHybrid(size_t listener) {
  if (lastGain_.size() <= listener) {
    lastGain_.resize(listener + 1, std::vector<float>(scene_->sources.size(), 0.f));
    lastBus_.resize(listener + 1, std::vector<int>(scene_->sources.size(), 0));
  }
  hybrid_->prepare(*simulation_, listener, inputs_.listeners[listener].position, sources_,
                   baked_.get(),
                   irs_[listener], lateIrs_[listener], lastGain_[listener], lastBus_[listener]);
}

std::vector<ImpulseResponse> PropagationStage::wholeIrs(size_t listener) const {
  std::vector<ImpulseResponse> out;
  wholeIrsInto(listener, out);
  return out;
}

void PropagationStage::wholeIrsInto(size_t listener, std::vector<ImpulseResponse>& out) const {
  const std::vector<ImpulseResponse>& early = irs_.at(listener);
  out.resize(early.size());
  if (!hybrid_ || listener >= lastGain_.size()) {
    for (size_t s = 0; s < early.size(); ++s) out[s].assignFrom(early[s]);
    return;
  }
  const std::vector<ImpulseResponse>& late = lateIrs_.at(listener);
  for (size_t s = 0; s < early.size(); ++s) {
    const ImpulseResponse& bus = late[size_t(lastBus_[listener][s])];
    const float g = lastGain_[listener][s];
    ImpulseResponse& x = out[s];
    x.resize(early[s].channels(), bus.samples(), bus.sampleRate());
    x.source = s;
    x.frame = early[s].frame;
    for (int c = 0; c < x.channels(); ++c) {
      float* y = x.channel(c);
      const float* b = bus.channel(c);
      const float* e = early[s].channel(c);
      for (size_t n = 0; n < x.samples(); ++n) y[n] = g * b[n];
      for (size_t n = 0; n < early[s].samples() && n < x.samples(); ++n) y[n] += e[n];
    }
  }
}

void PropagationStage::attachBake(std::shared_ptr<const BakedField> bake,
                                  BakeInterpolation settings) {
  bakedWave_.reset();
  if (bake && bake->hasWave()) {
    checkWaveBandsAllowed();
    if (bake->waveSampleRate != scene_->audio.sampleRate)
      throw InputError(bake->path, "wave/band",
                       "the wave band is stored at " + std::to_string(bake->waveSampleRate) +
                           " Hz, " + scene_->path + " plays at " +
                           std::to_string(scene_->audio.sampleRate) + " Hz: bake again");
    const size_t probes = bake->probes.size(), sources = bake->sources.size();
    auto set = std::make_unique<wave::WaveBandSet>(
        probes, sources, scene_->audio.output, bake->waveCrossoverHz, bake->waveMaxFrequencyHz,
        double(bake->waveSampleRate));
    for (size_t s = 0; s < sources; ++s)
      for (size_t p = 0; p < probes; ++p)
        if (bake->waveReached[s * probes + p])
          set->set(p, s, std::span<const float>(
                             bake->wave.data() + (s * probes + p) * bake->waveSamples,
                             bake->waveSamples));
    bakedWave_ = std::move(set);
    waveBlend_.reserve(size_t(std::max(1, settings.maxProbes)));  // no allocation per frame
  }
  baked_ =
      bake ? std::make_unique<BakedPlayback>(std::move(bake), *simulation_, settings) : nullptr;
}

}  // namespace dpc
