// A jamb's edge beside a leaf ajar, seen past a door stop. A box leaf closed against a stop and
// opened 2 to 5 degrees has its latch rim out of the reveal, or nearly: the opening between the
// rim and the jamb's corner is 5 mm to 3 cm wide, and the stop behind the jamb (or before it)
// hides the listener (or the source) from the jamb's edge. That edge's first-order path has a
// blocked leg, the leaf's channel along its latch face has nothing across it, and the level
// fell 5 to 10 dB below the leaf shut, where it should rise toward the slit model of the
// opening (Gomperts; Mechel: engine/slit.h).
//
// The jamb's path keeps its slit and leaves round the stop's corners as a turned channel's
// mouth is left (engine/channel_turn.h turnedLeg): free air, the detour's excess over the
// straight line taking the slit's field down by a screen's shadow loss (engine/slit.h
// SlitPath::shadowExcess). The slit's width is the narrowest section: the distance from the
// edge's line at Q to the nearest parallel rim of another body across free air (the leaf's),
// or the gap probe's width where that is narrower (engine/gap_probe.h: square to the edge, it
// takes a slanted opening for wider than it is); the slit has no depth and runs along the
// edge. A turn through a narrow gap, round the edge's own body or round the body across the
// gap is a channel's way (engine/channel_turn.h turnedChannel), not this.
//
// Internal to the engine (engine/diffraction.cpp). Any thread (reentrant: tracer queries
// only); allocates; no errors.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/diffraction.h"
#include "engine/edge_path.h"
#include "engine/surface_bound.h"

namespace dpc {

/// With the line of sight blocked: the paths over large bodies' static edges one of whose legs
/// is blocked within kChannelReach of the edge (BoundQuery::hidden), the other free, that pass
/// a gap no wider than the way to the turn's corner and turn round edges beside them (`near`:
/// per static edge, its chain neighbours, engine/edge_chain.h) to what the edge does not see;
/// `objects`' placed edges count as rims. Each is moved from q.hidden to `paths`. Up to
/// 8 + 2 n + n^2 rays per hidden path with n neighbours within reach (turnedLeg), then the
/// probe's and the same again for those that turn.
void addTurnedLegs(const std::vector<DiffractionEdge>& edges,
                   const std::vector<std::vector<uint32_t>>& near,
                   const std::vector<ObjectEdges>& objects, BoundQuery& q,
                   std::vector<EdgePath>& paths);

}  // namespace dpc
