#include "engine/simulation.h"

#include <chrono>

namespace dpc {

Simulation::Simulation(const SceneDesc& scene) : Simulation(scene, scene.propagation) {}

Simulation::Simulation(const SceneDesc& scene, const PropagationSettings& settings)
    : settings_(settings), listenerRadius_(scene.listener.radius) {
  geometry_ =
      std::make_unique<Geometry>(scene.mesh, scene.materials, settings_.patchSize, scene.objects);
  propagator_ = std::make_unique<Propagator>(*geometry_, settings_);
  if (settings_.diffraction) diffraction_ = std::make_unique<EdgeDiffraction>(scene.mesh);
  for (const SourceDesc& s : scene.sources) {
    sourcePositions_.push_back(s.position);
    if (settings_.estimator == Estimator::kDpc)
      caches_.push_back(std::make_unique<DiffusePathCache>(
          settings_.dpcWeighting, settings_.cacheTau, 1.0 / settings_.frameRate,
          size_t(double(settings_.cacheMemoryMb) * 1048576.0)));
    SourceResult r;
    r.energy = EnergyResponse(settings_.irLength, kEnergyBinSeconds);
    results_.push_back(std::move(r));
  }
}

void Simulation::enableDirectional(const std::vector<glm::vec3>& listenerDirections) {
  directional_.clear();
  for (size_t s = 0; s < results_.size(); ++s)
    directional_.emplace_back(settings_.irLength, kEnergyBinSeconds, listenerDirections);
}

double Simulation::boundingVolume() const {
  const glm::vec3 e = geometry_->boundsMax() - geometry_->boundsMin();
  return std::max(1.0, double(e.x) * e.y * e.z);
}

void Simulation::setObjectPoses(const std::vector<Pose>& poses) {
  for (size_t k = 0; k < poses.size() && k < geometry_->objectCount(); ++k)
    geometry_->setObjectPose(k, poses[k]);
  geometry_->commitPoses();
}

void Simulation::runFrame(const glm::vec3& listenerPosition) {
  runFrame(listenerPosition, sourcePositions_);
}

void Simulation::runFrame(const glm::vec3& listenerPosition,
                          const std::vector<glm::vec3>& sources) {
  const ListenerSphere listener{listenerPosition, listenerRadius_};
  for (size_t s = 0; s < results_.size() && s < sources.size(); ++s) {
    SourceResult& r = results_[s];
    const auto t0 = std::chrono::steady_clock::now();
    groups_.clear();
    r.trace = propagator_->traceFrame(frame_, uint32_t(s), sources[s], listener, groups_);
    const auto t1 = std::chrono::steady_clock::now();
    r.direct = propagator_->directSound(sources[s], listener);
    if (diffraction_)
      diffraction_->apply(*geometry_, sources[s], listener, settings_.speedOfSound,
                          propagator_->airAttenuationPerMetre(), r.direct);
    r.energy.clear();
    DirectionalEnergyResponse* dir = nullptr;
    if (!directional_.empty()) {
      dir = &directional_[s];
      dir->clear();
      dir->setListenerFrame(orientation_.forward(), orientation_.up());
    }
    if (caches_.empty()) {
      pathTracing_.endFrame(groups_, r.trace.rays, settings_.speedOfSound, r.energy, dir);
      r.cacheEntries = groups_.groups().size();
      r.cacheBytes = 0;
    } else {
      caches_[s]->endFrame(groups_, r.trace.rays, settings_.speedOfSound, r.energy, dir);
      r.cacheEntries = caches_[s]->entryCount();
      r.cacheBytes = caches_[s]->bytes();
      r.cacheCoarseEntries = caches_[s]->coarseEntryCount();
      r.cacheBudgetBytes = caches_[s]->budgetBytes();
      r.cacheMergedEntries = caches_[s]->mergedEntries();
      r.cacheCoarseEnergyFraction = caches_[s]->coarseEnergyFraction();
    }
    const auto t2 = std::chrono::steady_clock::now();
    r.traceSeconds = std::chrono::duration<double>(t1 - t0).count();
    r.estimatorSeconds = std::chrono::duration<double>(t2 - t1).count();
  }
  ++frame_;
}

}  // namespace dpc
