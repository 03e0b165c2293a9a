#include "runtime/response_snapshot.h"

namespace dpc {

bool ResponseSnapshot::tryStore(const PropagationStage& stage, const WorldState& world,
                                size_t listener, uint64_t frame) {
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return false;
  const Simulation& sim = stage.simulation();
  stage.wholeIrsInto(listener, irs_);
  energy_.resize(sim.sourceCount());
  direct_.resize(sim.sourceCount());
  paths_.resize(sim.sourceCount());
  for (size_t s = 0; s < sim.sourceCount(); ++s) {
    const Simulation::SourceResult& r = sim.result(s, listener);
    energy_[s] = r.energy.bins();
    direct_[s] = r.direct;
    paths_[s] = sim.specularPaths(s, listener);  // capacity reused: no allocation once grown
    // The direct sound (with its diffraction) is computed apart from the estimator's bins.
    const double k = r.direct.delaySeconds / r.energy.binSeconds();
    if (k >= 0.0 && k < double(energy_[s].size())) energy_[s][size_t(k)] += r.direct.intensity;
  }
  world_ = world;  // the vectors' capacity reused: no allocation once grown
  binSeconds_ = Simulation::kEnergyBinSeconds;
  frame_ = frame;
  valid_ = true;
  return true;
}

}  // namespace dpc
