// The paths round edges in series (engine/edge_chain.h) in the direct sound: laid per query
// with the line of sight blocked, over the static mesh's edges and each moving object's, and
// added to the held coherent sum of the first-order paths under engine/surface_bound.h
// chainBound.
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
