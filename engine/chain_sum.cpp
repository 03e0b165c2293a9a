#include "engine/chain_sum.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <glm/geometric.hpp>
#include <numbers>

#include "engine/barrier.h"
#include "engine/hull_ways.h"
#include "engine/object_edges.h"
#include "engine/openings.h"
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

/// The chains over the static mesh's edges `seeds` and a moving object's edges `own` (its
/// world edges' indices) together, each with at least one edge of either: a leaf opened 70-90
/// degrees, the way from the hinge jamb round the leaf's free rim. Only the seeds within
/// kChainReach of one of those edges take part; the two sets' neighbours are found among
/// themselves (chainNeighbours over these few edges, per query). None when either set is
/// empty. The chains' edge indices are into that local list (chains of two or more edges:
/// addObjectRims reads one-edge chains only).
std::vector<EdgeChain> mixedChains(const BoundQuery& q, const ObjectEdges& o,
                                   const std::vector<uint32_t>& seeds,
                                   const std::vector<uint32_t>& own, ChainBudget& budget) {
  std::vector<DiffractionEdge> edges;
  for (uint32_t i : seeds) {  // the static seeds within a chain's reach of the object's edges
    const DiffractionEdge& e = q.edges[i];
    if (std::any_of(own.begin(), own.end(), [&](uint32_t j) {
          return segmentGap(e.a, e.b, o.world[j].a, o.world[j].b) <= kChainReach;
        }))
      edges.push_back(e);
  }
  const auto objectFrom = uint32_t(edges.size());
  if (objectFrom == 0 || own.empty()) return {};  // no chain holds both kinds
  for (uint32_t i : own) edges.push_back(o.world[i]);
  std::vector<uint32_t> all(edges.size());
  for (uint32_t i = 0; i < uint32_t(all.size()); ++i) all[i] = i;
  return edgeChains(q.tracer, edges, chainNeighbours(edges), all, q.source, q.L, budget, 2,
                    objectFrom);
}

/// Per band, the largest of the chains' own gains (with their source weights `weights`) whose
/// opening (EdgeChain::opening, a slit path in `paths`) is wide, each weighted by how wide:
/// 1 - slitWeight at twice the opening's k w (engine/slit.h), which rises from 0 where the
/// opening is half a wavelength wide to 1 where it is one, while the slit model itself gives way
/// at two. Where an opening is wide, the way round the chain's rim is no quieter than the rim
/// alone makes it, while its slit path, a strip in a baffle, radiates little toward a listener
/// near the opening's plane: a leaf ajar 12 degrees, the listener on the doorway's axis behind
/// it, read 24.5 dB below the free field at 2 kHz through its 12 cm opening, where the rim's two
/// corners (the chain, ISO 9613-2's barrier) give 13.7 dB.
Bands wideOpeningGain(const std::vector<EdgeChain>& chains, const std::vector<Bands>& weights,
                      const std::vector<EdgePath>& paths, float direct, const BoundQuery& q) {
  Bands out(0.f);
  for (size_t c = 0; c < chains.size(); ++c) {
    if (chains[c].opening < 0) continue;
    const double width = double(paths[size_t(chains[c].opening)].gapWidth);
    const Bands own = chainGain(chains[c], direct, q.speedOfSound, q.airPerMetre) * weights[c];
    for (int b = 0; b < kNumBands; ++b) {
      const double kw = 2.0 * std::numbers::pi * bandCentreExactHz(b) / q.speedOfSound * width;
      const double wide = 1.0 - slitWeight(2.0 * kw, kSlitFullAspect);
      out[b] = std::max(out[b], float(wide) * own[b]);
    }
  }
  return out;
}

/// The flat surfaces (sorted, each once) of the small bodies (not largeBody) whose edges
/// (indices into q.edges) are listed.
std::vector<uint32_t> smallSurfaces(const BoundQuery& q, const std::vector<uint32_t>& edges) {
  std::vector<uint32_t> out;
  for (uint32_t i : edges)
    for (uint32_t s : q.edges[i].surfaces)
      if (smallBody(q.bodies, s)) out.push_back(s);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// The free field's intensity (1/m^2, omnidirectional) at distance d (m), with air absorption.
Bands omniAt(float d, const BoundQuery& q) {
  return exp(q.airPerMetre * -d) * (1.f / (4.f * std::numbers::pi_v<float> * d * d));
}

}  // namespace

double chainGainAt(const EdgeChain& chain, float direct, double lambda) {
  const double z = double(chain.length) - double(direct);
  const double span = chain.n >= 2 ? double(glm::distance(chain.q[0], chain.q[chain.n - 1])) : 0.0;
  return screenGain(lambda, z, span, int(chain.n));
}

Bands chainsGain(const std::vector<EdgeChain>& chains, const std::vector<Bands>& weights,
                 float direct, float speedOfSound, const Bands& airPerMetre) {
  Bands out(0.f);
  for (int band = 0; band < kNumBands; ++band) {
    double sum = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const double f = diffractionFrequencyHz(band, i), lambda = double(speedOfSound) / f;
      std::complex<double> p = 0.0;
      for (size_t c = 0; c < chains.size(); ++c) {
        const double air = std::exp(-double(airPerMetre[band]) * double(chains[c].length - direct));
        const double amplitude =
            std::sqrt(chainGainAt(chains[c], direct, lambda) * air * double(weights[c][band]));
        p += std::polar(amplitude, -2.0 * std::numbers::pi * double(chains[c].length) / lambda);
      }
      sum += std::norm(p);
    }
    out[band] = float(sum / kDiffractionFrequenciesPerBand);
  }
  return out;
}

Bands chainGain(const EdgeChain& chain, float direct, float speedOfSound,
                const Bands& airPerMetre) {
  return chainsGain({chain}, {Bands(1.f)}, direct, speedOfSound, airPerMetre);
}

Bands withChains(const std::vector<EdgePath>& paths, const std::vector<EdgeChain>& chains,
                 const DirectSound& coherent, const DirectSound& direct, const Bands& free,
                 const Bands& held, BoundQuery& q) {
  if (chains.empty()) return held;
  const float d = direct.distance;
  const Bands omni = omniAt(d, q);
  std::vector<Bands> weights = chainWeights(chains, q);
  const Bands wide = omni * wideOpeningGain(chains, weights, paths, d, q);
  const std::vector<Bands> unslit = chainUnslit(chains, paths, q.speedOfSound);
  for (size_t c = 0; c < chains.size(); ++c) weights[c] *= unslit[c];
  std::vector<ChainEnergy> energies;
  for (size_t c = 0; c < chains.size(); ++c) {
    const Bands own = chainGain(chains[c], d, q.speedOfSound, q.airPerMetre) * weights[c];
    ChainEnergy e{omni * own, {}};
    if (chains[c].object >= 0) e.surfaces = {kMovingObjects};
    for (size_t i = 0; i < chains[c].n && chains[c].object < 0; ++i)
      e.surfaces.insert(e.surfaces.end(), q.edges[chains[c].edge[i]].surfaces.begin(),
                        q.edges[chains[c].edge[i]].surfaces.end());
    if (chains[c].hull && chains[c].object < 0)  // it passes round the whole group of bodies
      e.surfaces.insert(e.surfaces.end(), q.hullSurfaces.begin(), q.hullSurfaces.end());
    energies.push_back(std::move(e));
  }
  const Bands chained = held + omni * chainsGain(chains, weights, d, q.speedOfSound, q.airPerMetre);
  return max(held, min(max(chained, wide), chainBound(paths, coherent, free, energies, q)));
}

std::vector<EdgeChain> laidChains(BoundQuery& q, const std::vector<ObjectEdges>& objects,
                                  const std::vector<std::vector<uint32_t>>& near,
                                  uint32_t& leftOut) {
  ChainBudget budget;
  std::vector<uint32_t> all;
  const std::vector<uint32_t> seeds =
      chainSeeds(q.crossed, q.bodies, q.edges, q.source, q.L, leftOut, &all);
  joinNeighbourBodies(q.bodies, q.edges, near, all, leftOut);
  q.hullSurfaces = smallSurfaces(q, all);
  std::vector<EdgeChain> out =
      edgeChains(q.tracer, q.edges, near, seeds, q.source, q.L, budget, 2, UINT32_MAX, &all);
  for (size_t k = 0; k < objects.size(); ++k) {
    const ObjectEdges& o = objects[k];
    if (!nearLine(o, q.source, q.L)) continue;
    ChainBudget own;  // an object's own: the static mesh's chains may have spent theirs
    std::vector<uint32_t> around;
    const std::vector<uint32_t> nearby = edgesNearLine(o.world, q.source, q.L, leftOut, &around);
    std::vector<EdgeChain> more =
        edgeChains(q.tracer, o.world, o.near, nearby, q.source, q.L, own, 1, 0, &around);
    const std::vector<EdgeChain> mixed = mixedChains(q, o, seeds, nearby, own);
    more.insert(more.end(), mixed.begin(), mixed.end());
    leftOut += own.leftOut;
    for (EdgeChain& c : more) c.object = int(k);
    out.insert(out.end(), more.begin(), more.end());
  }
  leftOut += budget.leftOut;
  return out;
}

}  // namespace dpc
