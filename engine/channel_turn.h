// A channel that turns at a mouth. Real doors close against a stop: a strip round the frame
// that the leaf's face overlaps by 10 to 25 mm, a few millimetres off it. Each gap then runs
// along the leaf's side face and turns between its face and the stop (an L-shaped gap), so from
// the channel's mouth by the stop the other room lies behind the stop and channelPath's leg
// there is blocked: a closed door with a stop passed nothing at all. Seen from off the axis the
// stop's own edge hides the listener too, and the wall's corner behind it may.
//
// The path leaves the channel's mouth point M (the back edge's point, or the front edge's for
// a stop on the source's side) by a chain of at most kChannelHops legs between edges near M,
// parallel to the channel's edges (setChannelNeighbours), each leg a straight segment square to
// them that meets nothing: the shortest chain from whose last edge the listener (or source) is
// seen, by relaxing over the hops (the edges are few: a stop's and a reveal's corners). The
// first leg continues the slit when it runs between two surfaces at most kChannelGapMax apart
// (between the leaf's face and the stop): its length, along the channel and then square to it
// (channelDepth), adds to the slit's depth, a bent slit taken as a straight one as long as its
// centre line (Mechel's transmission line through the bend: the width is far below the
// wavelength). The other legs are free air round the stop's corners: they add to the path's
// length, and their excess over the straight line from the slit's mouth takes the slit's field
// down by a screen's shadow loss past the shadow boundary (EdgePath::lipExcess, engine/slit.h
// SlitPath::shadowExcess).
//
// Internal to the engine (engine/diffraction.cpp). Any thread (reentrant: tracer queries
// only); allocates small vectors per query; no errors.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "engine/diffraction.h"
#include "engine/edge_path.h"
#include "engine/tracer.h"

namespace dpc {

/// m: how far from a channel's mouth edge the edges it may turn round lie (a stop's lip and
/// depth, the rest of the reveal beside it).
inline constexpr float kChannelReach = 0.1f;

/// The most edges looked at round one mouth (the nearest), and the most legs a turn takes.
inline constexpr size_t kChannelNeighbours = 8;
inline constexpr int kChannelHops = 3;

/// Sets each face's NarrowFace::near: per direction, the edges a channel may turn round past
/// its back edge, parallel to it (kParallelEdges), their lines within kChannelReach of its
/// line, overlapping it along its length, neither of the face's edges; the kChannelNeighbours
/// nearest, nearest first. Load time; the edges binned in a grid (linear in the edges and the
/// faces, about (length / 20 cm) * 27 cell look-ups per face's edge).
void setChannelNeighbours(const std::vector<DiffractionEdge>& edges,
                          std::vector<NarrowFace>& faces);

/// The channel from source over `front` along its face to `back` and on to the listener L
/// when a leg at a mouth is blocked and a turn round the edges near that mouth (`entries`
/// round front, `exits` round back: NarrowFace::near) reaches what the mouth does not see;
/// p as channelPath's, with EdgePath::before, beyond, lipBefore, lipBeyond set. False when
/// there is no gap across the front mouth (gapAcross) unless `open` (a small body's face,
/// whose opening may lie beside a mouth instead: engine/openings.h openChannel), both legs are
/// free (channelPath's case), or no turn reaches. Up to about 2 + 2 n + 2 n^2 rays per
/// blocked mouth (n <= kChannelNeighbours: the first legs, the further ones over
/// kChannelHops - 1 rounds, the goal rays and the first leg's two sides), then the legs' 2.
/// The chain is laid out at the straight channel's point; the turned path's point of least
/// length may lie a little along the edges from it, where only its outer legs are tested
/// again.
bool turnedChannel(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                   const DiffractionEdge& front, const DiffractionEdge& back,
                   const std::vector<uint32_t>& entries, const std::vector<uint32_t>& exits,
                   const glm::vec3& source, const glm::vec3& L, bool open, EdgePath& p);

/// First-order path p (edgePath's) whose leg to the listener (or from the source) is blocked
/// within kChannelReach of its point Q while the other is free (or free moved 2 mm aside: a leg
/// grazing another rim): a jamb's edge ajar from a leaf, the door stop behind the jamb in the
/// leg's way. The same path leaving Q round the edges `near` (their lines parallel to p's edge
/// and near it: a stop's corners) in free air, as a turned channel's mouth is left: p's
/// EdgePath::lipBeyond (or lipBefore), lipLength and lipExcess set, its length and arrival (or
/// leaving direction) with them, and no UTD field of its own (share 0, atEnd: the slit's field
/// only, engine/slit.h, as a channel's). False, p unchanged, when the legs are not so, no turn
/// reaches, or the turn's first leg runs in a narrow gap (a channel's way). Up to 8 + 2 n +
/// n^2 rays (n = near.size()).
bool turnedLeg(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
               const std::vector<uint32_t>& near, const glm::vec3& source, const glm::vec3& L,
               EdgePath& p);

}  // namespace dpc
