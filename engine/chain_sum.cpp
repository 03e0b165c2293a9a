#include "engine/chain_sum.h"

#include <glm/geometric.hpp>
#include <numbers>

#include "engine/object_edges.h"
#include "engine/slit.h"

namespace dpc {

namespace {

/// Per chain, the source's directivity weight toward its first edge (1 for an omni source).
std::vector<Bands> chainWeights(const std::vector<EdgeChain>& chains, const BoundQuery& q) {
  std::vector<Bands> out(chains.size(), Bands(1.f));
  if (q.directivity.omni()) return out;
  for (size_t c = 0; c < chains.size(); ++c)
    out[c] = directivityWeight(q.directivity,
                               glm::dot(q.forward, glm::normalize(chains[c].q[0] - q.source)));
  return out;
}

/// The band mean of (1 - s)^2, s = slitWeight of owner slit o (engine/slit.h): the energy share
/// its far edge keeps of its own UTD field.
Bands partnerShare(const EdgePath& o, float speedOfSound) {
  Bands out(0.f);
  for (int band = 0; band < kNumBands; ++band) {
    double sum = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const double k = 2.0 * std::numbers::pi * diffractionFrequencyHz(band, i) / speedOfSound;
      const double s = slitWeight(k * o.slit.sinBeta * o.slit.width, o.slitAspect);
      sum += (1.0 - s) * (1.0 - s);
    }
    out[band] = float(sum / kDiffractionFrequenciesPerBand);
  }
  return out;
}

/// A moving object's edge taken alone (a one-edge chain: objects have no first-order paths)
/// that lies across a slit a static edge found, closed by an object (a game door's free rim
/// ajar, across the latch gap from the jamb), is that slit's other edge: the slit's field,
/// which its owner carries, replaces its UTD field in the proportion s, as markSlitPartners
/// does for a static edge (engine/diffraction.cpp). Its weight is scaled by (1 - s)^2 per band.
/// Within 1.5 widths of the slit's far side, as acrossSlit (engine/edge_path.h) takes it. A rim
/// whose own probe finds the gap is a slit path instead (engine/diffraction.cpp addObjectRims);
/// this is for one whose probe finds none: the two_rooms door ajar 20 degrees read the open
/// doorway at 63 Hz, 6.2 dB above the same leaf in the static mesh.
void scaleSlitPartners(const std::vector<EdgePath>& paths, const std::vector<EdgeChain>& chains,
                       float speedOfSound, std::vector<Bands>& weights) {
  constexpr float kReach = 1.5f;  // widths
  for (size_t c = 0; c < chains.size(); ++c) {
    if (chains[c].object < 0 || chains[c].n != 1) continue;
    for (const EdgePath& o : paths) {
      if (!(o.gapWidth > 0.f) || !o.slitOwner || o.gapCloser != kMovingObjects ||
          glm::distance(chains[c].q[0], o.q + o.gapWidth * o.mouth) > kReach * o.gapWidth)
        continue;
      weights[c] *= partnerShare(o, speedOfSound);
      break;
    }
  }
}

}  // namespace

Bands withChains(const std::vector<EdgePath>& paths, const std::vector<EdgeChain>& chains,
                 const DirectSound& coherent, const DirectSound& direct, const Bands& free,
                 const Bands& held, BoundQuery& q) {
  if (chains.empty()) return held;
  const float d = direct.distance;
  const Bands omni = exp(q.airPerMetre * -d) * (1.f / (4.f * std::numbers::pi_v<float> * d * d));
  std::vector<Bands> weights = chainWeights(chains, q);
  scaleSlitPartners(paths, chains, q.speedOfSound, weights);
  std::vector<ChainEnergy> energies;
  for (size_t c = 0; c < chains.size(); ++c) {
    ChainEnergy e{omni * chainGain(chains[c], d, q.speedOfSound, q.airPerMetre) * weights[c], {}};
    if (chains[c].object >= 0) e.surfaces = {kMovingObjects};
    for (size_t i = 0; i < chains[c].n && chains[c].object < 0; ++i)
      e.surfaces.insert(e.surfaces.end(), q.edges[chains[c].edge[i]].surfaces.begin(),
                        q.edges[chains[c].edge[i]].surfaces.end());
    energies.push_back(std::move(e));
  }
  const Bands chained =
      held + omni * chainsGain(chains, weights, d, q.speedOfSound, q.airPerMetre);
  return max(held, min(chained, chainBound(paths, coherent, free, energies, q)));
}

std::vector<EdgeChain> laidChains(const BoundQuery& q, const std::vector<ObjectEdges>& objects,
                                  const std::vector<std::vector<uint32_t>>& near,
                                  uint32_t& leftOut) {
  ChainBudget budget;
  std::vector<EdgeChain> out = edgeChains(
      q.tracer, q.edges, near, chainSeeds(q.crossed, q.bodies, q.edges, q.source, q.L, leftOut),
      q.source, q.L, budget);
  for (size_t k = 0; k < objects.size(); ++k) {
    const ObjectEdges& o = objects[k];
    if (!nearLine(o, q.source, q.L)) continue;
    ChainBudget own;  // an object's own: the static mesh's chains may have spent theirs
    std::vector<EdgeChain> more =
        edgeChains(q.tracer, o.world, o.near, edgesNearLine(o.world, q.source, q.L, leftOut),
                   q.source, q.L, own, 1);
    leftOut += own.leftOut;
    for (EdgeChain& c : more) c.object = int(k);
    out.insert(out.end(), more.begin(), more.end());
  }
  leftOut += budget.leftOut;
  return out;
}

}  // namespace dpc
