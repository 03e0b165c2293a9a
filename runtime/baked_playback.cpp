#include "runtime/baked_playback.h"

namespace dpc {

BakedPlayback::BakedPlayback(std::shared_ptr<const BakedField> field, const Simulation& simulation,
                             BakeInterpolation settings)
    : interpolator_(std::move(field), simulation.tracer(), settings),
      baked_(simulation.sourceCount(), 0),
      energy_(simulation.settings().irLength, Simulation::kEnergyBinSeconds) {}

void BakedPlayback::setSources(const std::vector<glm::vec3>& positions) {
  for (size_t s = 0; s < baked_.size() && s < positions.size(); ++s)
    baked_[s] = interpolator_.isBaked(s, positions[s]) ? 1 : 0;
}

void BakedPlayback::locate(const glm::vec3& position) {
  located_ = interpolator_.locate(position);
  if (!located_) ++stats_.fallbacks;
}

bool BakedPlayback::useBake(size_t s) {
  const bool use = located_ && s < baked_.size() && baked_[s];
  ++(use ? stats_.bakedResponses : stats_.liveResponses);
  return use;
}

const EnergyResponse& BakedPlayback::energy(size_t s, const EnergyResponse& live) {
  if (!useBake(s)) return live;
  interpolator_.response(s, energy_);
  return energy_;
}

const DirectionalEnergyResponse& BakedPlayback::directional(size_t s,
                                                            const DirectionalEnergyResponse& live) {
  if (!useBake(s)) return live;
  directional_ = live;  // the live response's directions and listener frame (sizes match:
                        // no allocation after the first frame)
  interpolator_.directional(s, directional_);
  return directional_;
}

}  // namespace dpc
