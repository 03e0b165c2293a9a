#include "runtime/response_snapshot.h"

namespace dpc {
namespace {

/// The endpoints of the edges whose paths r's direct sound sums (no allocation once grown).
void edgesOf(const Simulation& sim, const Simulation::SourceResult& r,
             std::vector<std::array<glm::vec3, 2>>& out) {
  out.clear();
  if (!sim.diffraction()) return;
  const std::vector<DiffractionEdge>& all = sim.diffraction()->edges();
  for (uint32_t e : r.diffractionEdges) out.push_back({all[e].a, all[e].b});
}

}  // namespace

void ResponseSnapshot::storeEnergy(const PropagationStage& stage, size_t s, size_t listener) {
  const Simulation::SourceResult& r = stage.simulation().result(s, listener);
  const BakedPlayback* baked = stage.bakedPlayback();
  fromBake_[s] = baked && baked->plays(s, listener) ? 1 : 0;
  // The copy assignment reuses energy_[s]'s capacity: no allocation once grown.
  energy_[s] = r.energy;
  // A pair played from the bake is not traced (its response stays empty): the response its
  // IR was synthesised from is the bake's, interpolated again here (a weighted sum of at most
  // maxProbes rows, as BakedPlayback::energy does).
  if (fromBake_[s]) baked->interpolate(s, listener, energy_[s]);
  // The direct sound (with its diffraction) and the exact early paths are computed apart
  // from the estimator's bins (and from the bake's, which leaves the stored paths out).
  energy_[s].add(r.direct.delaySeconds, r.direct.intensity);
  addSpecularPaths(stage.simulation().specularPaths(s, listener), energy_[s]);
}

bool ResponseSnapshot::tryStore(const PropagationStage& stage, const WorldState& world,
                                size_t listener, uint64_t frame) {
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) {
    if (!skippedLast_) {
      skippedLast_ = true;
      return false;
    }
    writerWaiting_.store(true, std::memory_order_release);
    lock.lock();
    writerWaiting_.store(false, std::memory_order_release);
  }
  skippedLast_ = false;
  const Simulation& sim = stage.simulation();
  if (withIrs_) {
    stage.wholeIrsInto(listener, irs_);
  } else {
    irs_.resize(sim.sourceCount());  // empty IRs: no channels
  }
  energy_.resize(sim.sourceCount());
  direct_.resize(sim.sourceCount());
  paths_.resize(sim.sourceCount());
  edges_.resize(sim.sourceCount());
  fromBake_.resize(sim.sourceCount());
  surfaces_.resize(sim.sourceCount());
  for (size_t s = 0; s < sim.sourceCount(); ++s) {
    const Simulation::SourceResult& r = sim.result(s, listener);
    storeEnergy(stage, s, listener);
    direct_[s] = r.direct;
    paths_[s] = sim.specularPaths(s, listener);  // capacity reused: no allocation once grown
    edgesOf(sim, r, edges_[s]);
    surfaces_[s] = r.surfaces.surfaces();  // capacity reused: no allocation once grown
  }
  world_ = world;  // the vectors' capacity reused: no allocation once grown
  binSeconds_ = Simulation::kEnergyBinSeconds;
  frame_ = frame;
  valid_ = true;
  return true;
}

}  // namespace dpc
