// Edge paths whose leg threads a gap away from their edge (a thick wall's jamb seen through the
// 10 mm gap beside a leaf set in the middle of the wall): what passes there is that gap's slit's,
// not the edge's.
//
// Internal to the engine (engine/diffraction.cpp). Propagation thread (the Tracer's queries);
// allocates; no errors.
#pragma once

#include <vector>

#include "engine/edge_path.h"
#include "engine/surface_bound.h"

namespace dpc {

/// A path whose leg threads a gap (markThreads, run here: the channels, found after it, are
/// not marked) that a slit or channel path carries (the gap's two
/// surfaces belong to the bodies either side of that slit: the leaf and its wall) is neither a
/// free edge nor the mouth of a slit of its own: what passes there is that slit's. Counted, the
/// jamb took a closed door set in a thick wall to the open doorway's level at 250-500 Hz. A gap
/// no slit carries (between the slats of a screen, which the probe does not take for slits)
/// leaves the path as it was. Dropped paths go to q.closed, the first surface as their gap's
/// closer (taken away, the leg is free again: surface_bound.h).
void dropThreadedPaths(BoundQuery& q, std::vector<EdgePath>& paths);

}  // namespace dpc
