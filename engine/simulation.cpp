#include "engine/simulation.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "common/stopwatch.h"
#include "engine/embree_tracer.h"
#include "engine/workload.h"
#include "scene/orientation.h"
#include "scene/tracing_policy.h"
#include "scene/trajectory.h"

namespace dpc {

Simulation::Simulation(const SceneDesc& scene) : Simulation(scene, scene.propagation) {}

Simulation::Simulation(const SceneDesc& scene, const PropagationSettings& settings,
                       const Options& simulationOptions)
    : settings_(settings),
      listenerRadius_(scene.listeners.empty() ? ListenerDesc{}.radius
                                              : scene.listeners.front().radius),
      seed_(settings.seed) {
  geometry_ =
      std::make_unique<Geometry>(scene.mesh, scene.materials, settings_.patchSize, scene.objects);
  tracer_ = std::make_unique<EmbreeTracer>(scene.mesh, scene.objects);
  Propagator::Options options;
  options.traceMode = simulationOptions.traceMode;
  options.keyRule = simulationOptions.keyRule;
  if (settings_.diffraction) {
    diffraction_ = std::make_unique<EdgeDiffraction>(scene.mesh, scene.objects);
    smallFaces_ = std::make_unique<ReflectionScattering>(
        scene.mesh, diffraction_->surfaces(), diffraction_->edges(), diffraction_->bodies(),
        scene.objects, settings_.reflectionScattering);
    if (settings_.reflectionScattering) options.reflectionScattering = smallFaces_.get();
  }
  if (std::clamp(std::min(settings_.exactOrder, settings_.maxOrder), 0, kMaxExactOrder) > 0) {
    specularScene_ = std::make_unique<SpecularScene>(scene.mesh, scene.objects, *geometry_,
                                                     *tracer_, propagationAirAttenuation(settings_),
                                                     settings_.speedOfSound, smallFaces_.get());
    specularCandidates_ = std::make_unique<SpecularCandidates>();
    options.specularFaces = specularScene_->faces().faces();
  }
  propagator_ = std::make_unique<Propagator>(*geometry_, *tracer_, settings_, options);
  const size_t pairs = scene.sources.size() * std::max<size_t>(1, scene.listeners.size());
  cachePool_ = std::make_unique<CachePool>(size_t(cachePoolMbFor(settings_, pairs) * 1048576.0));
  for (const SourceDesc& s : scene.sources) {
    sourcePositions_.push_back(s.position);
    directivities_.push_back(s.directivity);
    initialForwards_.push_back(sourceForward(sourceRotationAt(s, 0.0)));
  }
  sourceForwards_ = initialForwards_;
  for (const ObjectDesc& o : scene.objects) initialObjectPoses_.push_back(objectPoseAt(o, 0.0));
  sourceCount_ = scene.sources.size();
  untraced_.reserve(sourceCount_);
  reserveListeners(1);
}

void Simulation::reserveListeners(size_t listeners) {
  for (; reserved_ < listeners; ++reserved_) {
    for (size_t s = 0; s < sourceCount_; ++s) {
      if (settings_.estimator == Estimator::kDpc)
        caches_.push_back(std::make_unique<DiffusePathCache>(
            settings_.dpcWeighting, settings_.cacheTau, 1.0 / settings_.frameRate,
            size_t(double(settings_.cacheMemoryMb) * 1048576.0), cachePool_.get()));
      if (specularScene_)
        specularCaches_.push_back(
            std::make_unique<SpecularPathCache>(exactPathRetention(), 1.0 / settings_.frameRate));
      idle_.push_back(0);
      SourceResult r;
      r.energy = EnergyResponse(settings_.irLength, kEnergyBinSeconds);
      results_.push_back(std::move(r));
      if (!directions_.empty())
        directional_.emplace_back(settings_.irLength, kEnergyBinSeconds, directions_);
      if (shOrder_ >= 0) shEnergy_.emplace_back(shOrder_, settings_.irLength, shBinSeconds_);
      tees_.emplace_back();
    }
    groups_.emplace_back();
    hits_.emplace_back();
  }
  hitPtrs_.clear();
  for (FrameHits& h : hits_) hitPtrs_.push_back(&h);
  if (orientations_.size() < listeners) orientations_.resize(listeners);
  directCache_.reserve(reserved_ * sourceCount_);
}

void Simulation::restart(uint64_t seed) {
  seed_ = seed;
  frame_ = 0;
  for (auto& cache : caches_) cache->clear();
  for (auto& cache : specularCaches_) cache->clear();
}

void Simulation::restartPair(size_t pair) {
  if (pair < caches_.size()) caches_[pair]->clear();
  if (pair < specularCaches_.size()) specularCaches_[pair]->clear();
}

void Simulation::restartSource(size_t source) {
  for (size_t l = 0; l < reserved_ && source < sourceCount_; ++l)
    restartPair(l * sourceCount_ + source);
}

void Simulation::restartListener(size_t listener) {
  for (size_t s = 0; s < sourceCount_ && listener < reserved_; ++s)
    restartPair(listener * sourceCount_ + s);
}

void Simulation::enableDirectional(const std::vector<glm::vec3>& listenerDirections) {
  directions_ = listenerDirections;
  directional_.clear();
  for (size_t i = 0; i < results_.size(); ++i)
    directional_.emplace_back(settings_.irLength, kEnergyBinSeconds, directions_);
}

void Simulation::enableShEnergy(int order, double binSeconds) {
  shOrder_ = order;
  shBinSeconds_ = binSeconds;
  shEnergy_.clear();
  for (size_t i = 0; i < results_.size(); ++i)
    shEnergy_.emplace_back(order, settings_.irLength, binSeconds);
}

ArrivalSink* Simulation::pairSink(size_t pair, size_t l) {
  DirectionalEnergyResponse* dir = directional_.empty() ? nullptr : &directional_[pair];
  ShEnergyResponse* sh = shEnergy_.empty() ? nullptr : &shEnergy_[pair];
  if (dir) {
    dir->clear();
    dir->setListenerFrame(orientations_[l].forward(), orientations_[l].up());
  }
  if (sh) sh->clear();
  if (dir && sh) {
    tees_[pair] = ArrivalTee(dir, sh);
    return &tees_[pair];
  }
  return dir ? static_cast<ArrivalSink*>(dir) : sh;
}

double Simulation::boundingVolume() const {
  const glm::vec3 e = geometry_->boundsMax() - geometry_->boundsMin();
  return std::max(1.0, double(e.x) * e.y * e.z);
}

FrameInputs Simulation::inputsAt(const glm::vec3& listenerPosition,
                                 const std::vector<glm::vec3>& sources) const {
  const ListenerSphere listener{listenerPosition, listenerRadius_};
  return inputsAt(std::span(&listener, 1), sources);
}

FrameInputs Simulation::inputsAt(std::span<const ListenerSphere> listeners,
                                 const std::vector<glm::vec3>& sources) {
  FrameInputs in;
  in.listeners.assign(listeners.begin(), listeners.end());
  in.sourcePositions = sources;
  return in;
}

void Simulation::applyInputs(const FrameInputs& in) {
  const std::vector<Pose>& poses = in.objectPoses.empty() ? initialObjectPoses_ : in.objectPoses;
  if (!in.objectPoses.empty() || objectsMoved_) {
    for (size_t k = 0; k < poses.size() && k < tracer_->objectCount(); ++k) {
      tracer_->setObjectPose(k, poses[k]);
      if (specularScene_) specularScene_->setObjectPose(k, poses[k]);
      if (smallFaces_) smallFaces_->setObjectPose(k, poses[k]);
    }
    tracer_->commitPoses();
    if (diffraction_) diffraction_->setObjectPoses(poses);
    objectsMoved_ = !in.objectPoses.empty();
  }
  directCache_.posesApplied(poses);
  for (size_t s = 0; s < sourceCount_; ++s)
    sourceForwards_[s] = s < in.sourceRotations.size() ? sourceForward(in.sourceRotations[s])
                                                       : initialForwards_[s];
  for (size_t l = 0; l < listenerCount_; ++l)
    orientations_[l] =
        l < in.listenerOrientations.size() ? in.listenerOrientations[l] : Orientation{};
  for (size_t s = 0; s < sourceCount_; ++s)
    if (in.sourceRestarted(s)) restartSource(s);
  for (size_t l = 0; l < listenerCount_; ++l)
    if (in.listenerRestarted(l)) restartListener(l);
  skip_.assign(in.skippedPairs.begin(), in.skippedPairs.end());
  rays_ = std::max(1, in.raysPerEmitter > 0 ? in.raysPerEmitter : settings_.raysPerFrame);
  includeDirectRays_ = in.includeDirectRays;
}

TraceRequest Simulation::requestFor(uint32_t emitter, const glm::vec3& origin) const {
  TraceRequest rq;
  rq.seed = seed_;
  rq.frame = frame_;
  rq.emitter = emitter;
  rq.origin = origin;
  rq.rays = rays_;
  rq.includeDirectRays = includeDirectRays_;
  return rq;
}

void Simulation::runFrame(const FrameInputs& inputs) {
  if (inputs.listeners.empty())
    throw std::invalid_argument("Simulation::runFrame: the frame has no listener");
  if (inputs.sourcePositions.size() != sourceCount_)
    throw std::invalid_argument("Simulation::runFrame: " +
                                std::to_string(inputs.sourcePositions.size()) +
                                " source positions for " + std::to_string(sourceCount_) +
                                " sources");
  const size_t L = inputs.listeners.size();
  reserveListeners(L);
  listenerCount_ = L;
  applyInputs(inputs);
  // Every cache's frame share of the pool, fixed before any tracing thread asks for one.
  cachePool_->beginFrame(caches_.size());
  frameTrace_ = TraceStats{};
  frameTimes_ = FrameTimes{};
  if (tracesFromListeners(settings_.tracing, sourceCount_, L))
    traceFromListeners(inputs.listeners, inputs.sourcePositions);
  else
    traceFromSources(inputs.listeners, inputs.sourcePositions);
  // Growths the frame shares refused, retried one cache after another in pair order from the
  // pool's free bytes: deterministic, and a cache that needs more than a share still grows.
  const auto t0 = std::chrono::steady_clock::now();
  cachePool_->beginFrame(1);
  for (const std::unique_ptr<DiffusePathCache>& c : caches_) c->growDeferred();
  frameTimes_.pool = secondsSince(t0);
  sumPairTimes(L);
  ++frame_;
}

void Simulation::finishPairs(size_t count, const std::function<void(size_t)>& finish) {
  const auto t0 = std::chrono::steady_clock::now();
  propagator_->forEachParallel(count, finish);
  frameTimes_.pairs += secondsSince(t0);
}

void Simulation::sumPairTimes(size_t listeners) {
  for (size_t pair = 0; pair < listeners * sourceCount_; ++pair) {
    const SourceResult& r = results_[pair];
    frameTimes_.directCpu += r.directSeconds;
    frameTimes_.exactCpu += r.specularSeconds;
    frameTimes_.estimatorCpu += r.estimatorSeconds;
  }
}

bool Simulation::skippedForAll(size_t s, size_t listeners) const {
  for (size_t l = 0; l < listeners; ++l)
    if (!skipped(s, l)) return false;
  return listeners > 0;
}

void Simulation::traceFromSources(std::span<const ListenerSphere> listeners,
                                  const std::vector<glm::vec3>& sources) {
  untraced_.clear();
  for (size_t s = 0; s < sourceCount_ && s < sources.size(); ++s) {
    if (skippedForAll(s, listeners.size())) {
      untraced_.push_back(s);  // capacity: sourceCount_ (reserveSourceGroups)
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    for (size_t l = 0; l < listeners.size(); ++l) hits_[l].clear();
    TraceRequest rq = requestFor(uint32_t(s), sources[s]);
    rq.pattern = directivities_[s];
    rq.forward = sourceForwards_[s];
    rq.receivers = listeners;
    if (specularCandidates_) specularCandidates_->clear();
    const TraceStats trace = propagator_->traceFrame(
        rq, std::span(hitPtrs_.data(), listeners.size()), specularCandidates_.get());
    if (specularCandidates_) specularCandidateOverflow_ += specularCandidates_->overflow();
    const double traceSeconds = secondsSince(t0);
    addPass(trace, traceSeconds);
    // Each listener's direct sound (with edge diffraction) and estimator update touch only
    // that source-listener pair's data: run them concurrently on the tracing threads. Each
    // pair's float operations are the same whatever the thread, so results do not change.
    finishPairs(listeners.size(), [&](size_t l) {
      finishPair(s, l, sources[s], listeners[l], trace, traceSeconds, hits_[l], groups_[l]);
    });
  }
  if (!untraced_.empty()) finishUntraced(listeners, sources);
}

void Simulation::finishUntraced(std::span<const ListenerSphere> listeners,
                                const std::vector<glm::vec3>& sources) {
  for (size_t l = 0; l < listeners.size(); ++l) {
    const auto t0 = std::chrono::steady_clock::now();
    TraceStats trace;
    if (specularCandidates_) {
      specularCandidates_->clear();
      trace = propagator_->proposeSpecular(requestFor(uint32_t(l), listeners[l].position),
                                           *specularCandidates_);
      specularCandidateOverflow_ += specularCandidates_->overflow();
    }
    const double traceSeconds = secondsSince(t0);
    addPass(trace, traceSeconds);
    finishPairs(untraced_.size(), [&](size_t i) {
      const size_t s = untraced_[i];
      finishPair(s, l, sources[s], listeners[l], trace, traceSeconds, noHits_, noGroups_);
    });
  }
}

void Simulation::addPass(const TraceStats& t, double seconds) {
  frameTimes_.trace += seconds;
  frameTrace_ += t;
}

void Simulation::reserveSourceGroups() {
  if (sourceGroups_.size() >= sourceCount_) return;
  sourceGroups_.resize(sourceCount_);
  sourceHits_.resize(sourceCount_);
  sourceHitPtrs_.clear();
  for (FrameHits& h : sourceHits_) sourceHitPtrs_.push_back(&h);
  sourceSpheres_.resize(sourceCount_);
  liveHitPtrs_.resize(sourceCount_, nullptr);
  livePatterns_.resize(sourceCount_);
  liveForwards_.resize(sourceCount_);
  liveIds_.resize(sourceCount_, 0);
}

size_t Simulation::compactSources(size_t l, const ListenerSphere& listener,
                                  const std::vector<glm::vec3>& sources, size_t S) {
  size_t n = 0;
  for (size_t s = 0; s < S; ++s) {
    sourceHits_[s].clear();
    if (skipped(s, l)) continue;
    sourceSpheres_[n] = ListenerSphere{sources[s], listener.radius};
    liveHitPtrs_[n] = sourceHitPtrs_[s];
    livePatterns_[n] = directivities_[s];
    liveForwards_[n] = sourceForwards_[s];
    liveIds_[n] = uint32_t(s);
    ++n;
  }
  return n;
}

void Simulation::traceFromListeners(std::span<const ListenerSphere> listeners,
                                    const std::vector<glm::vec3>& sources) {
  reserveSourceGroups();
  const size_t S = std::min(sourceCount_, sources.size());
  for (size_t l = 0; l < listeners.size(); ++l) {
    const auto t0 = std::chrono::steady_clock::now();
    // The spheres of the sources traced for this listener, keyed by their source index so
    // that a pair's path identifiers do not depend on which others are left out.
    const size_t n = compactSources(l, listeners[l], sources, S);
    TraceRequest rq = requestFor(uint32_t(l), listeners[l].position);
    rq.fromListener = true;
    rq.receivers = std::span(sourceSpheres_.data(), n);
    rq.receiverIds = std::span(liveIds_.data(), n);
    rq.receiverPatterns = std::span(livePatterns_.data(), n);
    rq.receiverForwards = std::span(liveForwards_.data(), n);
    if (specularCandidates_) specularCandidates_->clear();
    TraceStats trace;
    if (n > 0)
      trace = propagator_->traceFrame(rq, std::span(liveHitPtrs_.data(), n),
                                      specularCandidates_.get());
    else if (specularCandidates_)
      trace = propagator_->proposeSpecular(rq, *specularCandidates_);
    if (specularCandidates_) specularCandidateOverflow_ += specularCandidates_->overflow();
    const double traceSeconds = secondsSince(t0);
    addPass(trace, traceSeconds);
    finishPairs(S, [&](size_t s) {
      finishPair(s, l, sources[s], listeners[l], trace, traceSeconds, sourceHits_[s],
                 sourceGroups_[s]);
    });
  }
}

void Simulation::finishPair(size_t s, size_t l, const glm::vec3& source,
                            const ListenerSphere& listener, const TraceStats& trace,
                            double traceSeconds, const FrameHits& hits, FrameGroups& groups) {
  const size_t pair = l * sourceCount_ + s;
  SourceResult& r = results_[pair];
  r.trace = trace;
  r.traceSeconds = traceSeconds;
  const auto t0 = std::chrono::steady_clock::now();
  if (!directCache_.holds(pair, source, sourceForwards_[s], listener)) {  // else as it was
    r.direct = propagator_->directSound(source, listener, directivities_[s], sourceForwards_[s]);
    if (diffraction_)
      diffraction_->apply(*tracer_, source, listener, settings_.speedOfSound,
                          propagator_->airAttenuationPerMetre(), r.direct, directivities_[s],
                          sourceForwards_[s], &r.diffractionEdges);
    directCache_.computed(pair, source, sourceForwards_[s], listener);
  }
  r.directSeconds = secondsSince(t0);
  // The frame's exact paths first: a hit is left out exactly when the exact path of its own
  // sequence is in this frame's paths (FrameHits::groupInto), so nothing counts twice.
  if (specularScene_) updateSpecular(pair, source, listener, r);
  const auto t1 = std::chrono::steady_clock::now();
  r.energy.clear();
  r.surfaces.clear();
  if (!skipped(s, l)) {
    groups.clear();
    hits.groupInto(groups, specularScene_ ? &specularCaches_[pair]->validKeys() : nullptr,
                   recordSurfaces_ ? &r.surfaces : nullptr);
    if (r.trace.rays > 0) r.surfaces.scale(1.f / float(r.trace.rays));
  }
  updateOrIdle(pair, groups, r, pairSink(pair, l));
  r.estimatorSeconds = secondsSince(t1);
}

void Simulation::updateSpecular(size_t pair, const glm::vec3& source,
                                const ListenerSphere& listener, SourceResult& r) {
  const auto t0 = std::chrono::steady_clock::now();
  SpecularPathCache& cache = *specularCaches_[pair];
  const uint64_t geometry = directCache_.geometryVersion();
  cache.update(*specularCandidates_, *specularScene_,
               {source, listener.position, listener.radius, geometry}, frame_);
  if (const size_t s = pair % sourceCount_; !directivities_[s].omni())
    cache.weightBySource(directivities_[s], sourceForwards_[s], source);
  r.specularPaths = cache.paths().size();
  r.specularCandidates = specularCandidates_->sequences().size();
  r.specularCacheEntries = cache.entryCount();
  r.specularOverflow = cache.overflow() + specularCandidateOverflow_;
  r.specularSeconds = secondsSince(t0);
}

const std::vector<SpecularPath>& Simulation::specularPaths(size_t source, size_t listener) const {
  static const std::vector<SpecularPath> kNone;
  if (specularCaches_.empty()) return kNone;
  return specularCaches_[listener * sourceCount_ + source]->paths();
}

void Simulation::updateOrIdle(size_t pair, const FrameGroups& groups, SourceResult& r,
                              ArrivalSink* dir) {
  if (pair < skip_.size() && skip_[pair]) {
    idle_[pair] = 1;  // the response stays empty: the bake plays it
    return;
  }
  if (idle_[pair] && pair < caches_.size()) caches_[pair]->clear();
  idle_[pair] = 0;
  updateEstimator(pair, groups, r, dir);
}

void Simulation::updateEstimator(size_t pair, const FrameGroups& groups, SourceResult& r,
                                 ArrivalSink* dir) {
  if (caches_.empty()) {
    pathTracing_.endFrame(groups, r.trace.rays, settings_.speedOfSound, r.energy, dir);
    r.cacheEntries = groups.groups().size();
    r.cacheBytes = 0;
    return;
  }
  DiffusePathCache& cache = *caches_[pair];
  cache.endFrame(groups, r.trace.rays, settings_.speedOfSound, r.energy, dir);
  r.cacheEntries = cache.entryCount();
  r.cacheBytes = cache.bytes();
  r.cacheCoarseEntries = cache.coarseEntryCount();
  r.cacheBudgetBytes = cache.budgetBytes();
  r.cacheMergedEntries = cache.mergedEntries();
  r.cachePoolBytes = cachePool_->budgetBytes();
  r.cachePoolUsedBytes = cachePool_->usedBytes();
  r.cachePoolRefusals = cache.refusedGrowths();
  r.cacheCoarseEnergyFraction = cache.coarseEnergyFraction();
}

}  // namespace dpc
