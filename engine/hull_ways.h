// The way round a group of bodies in line: posts of a fence or a colonnade seen along its
// length, slats seen end on. The chains of engine/edge_chain.h are searched edge by edge over
// each edge's nearest parallel neighbours, and a corner the path only grazes (a middle post's,
// on the straight line along the row's side) is no corner it wraps: the way round three posts
// in line wraps the first post's near corner and the last one's far corner, which lie further
// apart than the neighbours kept, so the search edge by edge does not find it.
//
// The edges of one direction, seen along it, are points in the plane square to it; the way
// round them on either side of the line of sight is the hull of those points with the source
// and the listener (A. M. Andrew, "Another efficient algorithm for convex hulls in two
// dimensions", Information Processing Letters 9, 1979: the monotone chain), from the source to
// the listener: its corners between the two are the edges a chain wraps, in order. Corners in
// line with their neighbours (turning by under kHullCollinear) are left out. Each way is
// offered to the chain search as one more candidate; it stands or not by the same tests.
//
// The edges are those of the bodies the line of sight crosses and of the small bodies joined
// to them (joinNeighbourBodies): behind a slatted screen the line of sight crosses one slat,
// and the way round the screen's end wraps the end slat's corners.
//
// Internal to the engine (engine/edge_chain.cpp, engine/chain_sum.cpp). Any thread; allocates
// small vectors; no rays; no errors.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "engine/diffraction.h"

namespace dpc {

/// radians: how far the way must turn at a hull corner for it to be one (the corners of the
/// middle posts in a row lie on the straight line along its side, to rounding; the first
/// post's near corner, 1 cm off the line of sight 3 m away, turns it by 3e-3).
inline constexpr float kHullCollinear = 1e-5f;

/// For each group of parallel edges (engine/edge_path.h kParallelEdges) among `seeds` (indices
/// into edges) and each side of the line of sight from source to L (m), the edges the way round
/// their hull wraps, in order from the source; only ways of two edges or more (one is a
/// first-order path) whose edges all lie between the source and L along the line of sight.
std::vector<std::vector<uint32_t>> hullWays(const std::vector<DiffractionEdge>& edges,
                                            const std::vector<uint32_t>& seeds,
                                            const glm::vec3& source, const glm::vec3& L);

/// Bodies at most: how many small bodies joinNeighbourBodies adds (a screen of 100 slats).
inline constexpr size_t kHullBodies = 128;

/// Adds to `candidates` (indices into edges: the edges of the bodies the line of sight crosses
/// within kChainSearch of it, engine/edge_chain.h chainSeeds' `all`) every edge of every small
/// body (not largeBody, not a moving object's) joined to a small candidate's body by parallel
/// neighbours (`near`, chainNeighbours), body by body, however far from the line of sight: the
/// slats of a screen beside the one the line of sight crosses, whose end slats the ways round
/// the screen wrap. Large bodies (a room, a wall) are neither joined nor joined through: their
/// far corners would set the hull. Past kHullBodies joined, nothing is added (a hull cut off
/// there would wrap a body inside the group as its end) and `leftOut` is increased by one. Any
/// thread; allocates; no rays; no errors.
void joinNeighbourBodies(const SurfaceBodies& bodies, const std::vector<DiffractionEdge>& edges,
                         const std::vector<std::vector<uint32_t>>& near,
                         std::vector<uint32_t>& candidates, uint32_t& leftOut);

}  // namespace dpc
