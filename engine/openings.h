// Openings a diffracted path leaves through, beside the edge it turns round. A free edge's UTD
// field and a chain's barrier term (engine/edge_chain.h, ISO 9613-2) know nothing of a surface
// a few centimetres past the edge. A door leaf ajar 3-30 degrees is the case: the path round
// its latch end passes between the leaf's rim and the jamb's corner (2 to 25 cm apart, at a
// slant the gap probe of engine/gap_probe.h takes for another edge's shadow), and the path
// over its top passes under the lintel. Below the slit's first cross mode that opening passes
// what a slit passes (Gomperts 1964; Mechel 1986: engine/slit.h), not what a free edge does:
// taken as free edges, a box leaf ajar 4-20 degrees read the open doorway's level at 63 Hz,
// 4-6 dB above the slit model of its opening, and the level stepped by 5-11 dB as the leaf
// turned a degree (where the probe found the opening, or lost it).
//
// The opening beside an edge at the path's point Q: rays from Q square to the edge, fanned
// 5-60 degrees (to 85 for a large body's face) from the leg toward the listener (or the source)
// away from the side the path turns round; the nearest surface they meet within a quarter of
// the edge's length (a slit's least aspect, engine/slit.h kSlitMinAspect) and kOpeningReach.
// Its width is that point's distance from the edge's line; the slit runs along the edge,
// without depth, its legs straight to its centre line (engine/edge_path.h makeSlit). Where a
// path already carries that opening's slit (a jamb's edge path whose probe met the leaf, a
// channel along the face a chain crosses), the edge or chain is that slit's other side and
// takes its share. A chain's opening no path carries becomes a slit path of its own, summed
// with the others in pressure, as far as its path length is known (EdgePath::phaseSpread: the
// opening's width).
//
// Internal to the engine (engine/diffraction.cpp, engine/chain_sum.cpp). Any thread
// (reentrant: tracer queries only): 17 rays per side looked at, up to 34 per free path, chain
// or channel, once each; allocates; no errors.
#pragma once

#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"
#include "engine/edge_chain.h"
#include "engine/edge_path.h"
#include "engine/surface_bound.h"

namespace dpc {

/// m: the widest opening taken as a slit (a leaf ajar 30 degrees opens 0.5 m), and the widest
/// looked for as another path's slit (a jamb's, whose probe met the leaf: the leaf's rim is its
/// other side; a leaf opened 50 degrees, 0.8 m).
inline constexpr float kOpeningReach = 0.5f;
inline constexpr float kPartnerReach = 1.f;

/// With the line of sight blocked: first each channel with nothing across its face takes the
/// opening at its mouth where that is wider than its probed gap; then each first-order path
/// over a small body's edge (a leaf's rim, static or a moving object's) whose opening the fan
/// finds (where it has no slit, one too short along its edge, one at least 1.1 times as wide,
/// or one closed by the same body) becomes a slit path: the other side of a path that carries
/// that slit already (takeSlit), else its own slit's owner. The paths that had taken its old
/// slit as theirs are freed; the caller settles owners and partners again (markSlitOwners,
/// markSlitPartners).
void openFreeEdges(std::vector<EdgePath>& paths, const BoundQuery& q);

/// Whether openFreeEdges would give free path p a slit: an opening beside its edge (toward the
/// listener, else the source) narrow enough for its own, or one a path in `paths` carries. A
/// moving object's rim whose gap the probe does not find becomes a path for it.
bool hasOpening(const EdgePath& p, const BoundQuery& q, const std::vector<EdgePath>& paths);

/// A channel p that turns at a mouth (engine/channel_turn.h) along a face with nothing across
/// it (a box leaf closed against a stop and opened 3-5 degrees: its latch face out of the
/// reveal, the stop in the back leg's way): the gap probe does not test the turned mouth's leg
/// and finds nothing. Its slit is the opening beside that mouth, the fan looking along the leg
/// to the turn's last corner (the stop's) and meeting the wall past the leaf's rim, without
/// depth, when at most `widest` metres and no path in `paths` carries it: p's gap, slit and
/// closer set, true; false, p unchanged, when none.
bool openChannel(EdgePath& p, const BoundQuery& q, float widest,
                 const std::vector<EdgePath>& paths);

/// With the line of sight blocked, after openFreeEdges: per chain with an opening beside its
/// last edge (toward L), else its first, that no path carries yet and a slit's reach holds,
/// the opening's own slit path (no UTD field, its slit's owner) added to `paths`, summed with
/// them in pressure. Chains ending on one rim share it. Sets each chain's EdgeChain::opening
/// to the path that carries its opening (that one, another's, or a channel's over its two
/// rims), -1 where none does. A chain with a leg through a gap (EdgeChain::gapLeg) between a
/// small body's edge and a large body's takes the opening beside the small body's end, looked
/// for across the leg away from the body, as its own slit path with the chain's detours on
/// both sides; where none is found within a slit's reach, a path carries it already (a gap the
/// probe found), or both ends are small bodies', the chain is removed.
void addChainOpenings(std::vector<EdgeChain>& chains, std::vector<EdgePath>& paths,
                      const BoundQuery& q);

/// Per chain, the energy factor on its own pressure where a path carries its opening
/// (EdgeChain::opening, set by addChainOpenings): (1 - s)^2 averaged over the band, s =
/// slitWeight(k_t w, aspect) of that path's slit at speed of sound `speedOfSound` (m/s); 1 for
/// a chain with none. The opening's field is that path's. No rays.
std::vector<Bands> chainUnslit(const std::vector<EdgeChain>& chains,
                               const std::vector<EdgePath>& paths, float speedOfSound);

}  // namespace dpc
