// The paths round edges in series (engine/edge_chain.h) in the direct sound: laid per query
// with the line of sight blocked, over the static mesh's edges and each moving object's, and
// added to the held coherent sum of the first-order paths under engine/surface_bound.h
// chainBound, each at its level (ISO 9613-2:1996 eq. (14), engine/edge_chain.h's file comment)
// and with its length's phase.
//
// Internal to the engine (engine/diffraction.cpp). Propagation thread (the Tracer's queries);
// allocates; no errors.
#pragma once

#include <cstdint>
#include <vector>

#include "common/bands.h"
#include "engine/diffraction.h"
#include "engine/edge_chain.h"
#include "engine/edge_path.h"
#include "engine/surface_bound.h"

namespace dpc {

/// ISO 9613-2's barrier attenuation of a chain at wavelength lambda (m) as an energy ratio over
/// the free field at the direct distance `direct` (m): engine/barrier.h screenGain with the
/// chain's excess and span. Any thread; no errors.
double chainGainAt(const EdgeChain& chain, float direct, double lambda);

/// A chain's energy over the free field at the direct distance `direct` (m), per band:
/// chainGainAt averaged over the band's frequencies (diffractionFrequencyHz), with the air's
/// attenuation over the path's extra length (airPerMetre per band, energy per m).
/// speedOfSound in m/s.
Bands chainGain(const EdgeChain& chain, float direct, float speedOfSound, const Bands& airPerMetre);

/// The chains together over the free field at the direct distance, per band: each chain's
/// pressure sqrt(chainGainAt x air x weights[c]) e^{-jk length} summed, |sum|^2 averaged over
/// the band's frequencies (the two sides of a pillar add in phase behind it, as its wave field
/// does; chains whose lengths differ across a band add as energies). weights: per chain, an
/// energy weight per band (the source's directivity toward its first edge).
Bands chainsGain(const std::vector<EdgeChain>& chains, const std::vector<Bands>& weights,
                 float direct, float speedOfSound, const Bands& airPerMetre);

/// The held sum with the chains round edges in series added (engine/edge_chain.h: their
/// coherent sum over the free field at the direct distance), at most what chainBound allows
/// (each chain's own energy and its edges' flat surfaces) and never below the held sum itself.
Bands withChains(const std::vector<EdgePath>& paths, const std::vector<EdgeChain>& chains,
                 const DirectSound& coherent, const DirectSound& direct, const Bands& free,
                 const Bands& held, BoundQuery& q);

/// The chains round edges in series with the line of sight blocked: over the static mesh's
/// edges near the bodies it crosses (two or more), and over each moving object's edges near it
/// (one or more: objects have no first-order paths). leftOut counts what the caps left out.
/// Sets q.hullSurfaces.
std::vector<EdgeChain> laidChains(BoundQuery& q, const std::vector<ObjectEdges>& objects,
                                  const std::vector<std::vector<uint32_t>>& near,
                                  uint32_t& leftOut);

}  // namespace dpc
