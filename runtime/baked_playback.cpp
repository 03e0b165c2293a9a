#include "runtime/baked_playback.h"

namespace dpc {

BakedPlayback::BakedPlayback(std::shared_ptr<const BakedField> field, const Simulation& simulation,
                             BakeInterpolation settings)
    : field_(std::move(field)),
      simulation_(simulation),
      settings_(settings),
      baked_(simulation.sourceCount(), 0),
      energy_(simulation.settings().irLength, Simulation::kEnergyBinSeconds) {
  interpolators_.push_back(
      std::make_unique<BakeInterpolator>(field_, simulation_.tracer(), settings_));
}

void BakedPlayback::beginFrame(std::span<const glm::vec3> sources,
                               std::span<const ListenerSphere> listeners) {
  for (size_t s = 0; s < baked_.size(); ++s)
    baked_[s] = s < sources.size() && interpolators_.front()->isBaked(s, sources[s]) ? 1 : 0;
  while (interpolators_.size() < listeners.size())
    interpolators_.push_back(
        std::make_unique<BakeInterpolator>(field_, simulation_.tracer(), settings_));
  located_.resize(listeners.size());
  pairs_.resize(listeners.size() * baked_.size());
  for (size_t l = 0; l < listeners.size(); ++l) {
    located_[l] = interpolators_[l]->locate(listeners[l].position) ? 1 : 0;
    if (!located_[l]) ++stats_.fallbacks;
    for (size_t s = 0; s < baked_.size(); ++s)
      pairs_[l * baked_.size() + s] = located_[l] && baked_[s] ? 1 : 0;
  }
}

bool BakedPlayback::useBake(size_t s, size_t listener) {
  const bool use = plays(s, listener);
  ++(use ? stats_.bakedResponses : stats_.liveResponses);
  return use;
}

const EnergyResponse& BakedPlayback::energy(size_t s, size_t listener,
                                            const EnergyResponse& live) {
  if (!useBake(s, listener)) return live;
  interpolators_[listener]->response(s, energy_);
  return energy_;
}

const DirectionalEnergyResponse& BakedPlayback::directional(size_t s, size_t listener,
                                                            const DirectionalEnergyResponse& live) {
  if (!useBake(s, listener)) return live;
  directional_ = live;  // the live response's directions and listener frame (sizes match:
                        // no allocation after the first frame)
  interpolators_[listener]->directional(s, directional_);
  return directional_;
}

}  // namespace dpc
