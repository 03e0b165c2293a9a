// Small bodies beside or across the direct sound's line of sight (engine/surface_bound.h): a
// seat, a slat, a leaf seen edge on. UTD sums each edge as an infinite one's; a body smaller
// than the wavelength, or thin as the passing sound sees it, scatters weakly, which those sums
// miss both ways. These bounds and floors compare the sum with the same sum without the bodies
// (surface_bound.h sumWithout).
//
// Internal to the engine. Propagation thread (the Tracer's queries); allocates; no errors.
#pragma once

#include <cstdint>
#include <vector>

#include "common/bands.h"
#include "engine/edge_path.h"
#include "engine/propagation.h"
#include "engine/surface_bound.h"

namespace dpc {

/// Per group of small surfaces (smallSurfaces), at most the sum without it times kLitRipple in
/// the bands whose wavelength exceeds its extent and twice its least path excess (heldBound);
/// `sum` the coherent sum with everything in place but the surfaces `base` (sorted; the groups
/// are those of the paths without them, and each group goes with them).
/// Also fills q.smallFloor when the line of sight is free and `base` empty: what the small
/// bodies together leave the sum at least (smallGroupsBound in engine/small_bodies.cpp; the
/// same floor as thinBodiesFloor's, at most the direct sound times what their slots pass). Band
/// intensities in 1/m^2; 1e30 where no bound holds.
Bands smallSurfaceBound(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                        const Bands& sum, BoundQuery& q, const std::vector<uint32_t>& base = {});

/// With the line of sight blocked only by bodies that stand free (whole bodies or closed solids,
/// none closed by the probe to a surface not taken away with them) and are thin as the sound
/// passing sees them (their silhouette along the line of sight a wide, k a <= 1/8; bodies within
/// 1 mm of each other one silhouette), in those bands at least the scene without them (and the
/// small bodies within 3 cm of them: the whole screen), the line of sight free, over
/// kLitRipple, times what the slots between them pass (a layer of slot air
/// per row: Morse & Ingard, Theoretical Acoustics, 9.4), and no more than `free` over it. With
/// slots between them, bodies thin at 63 Hz keep that floor in every band where each is under
/// half a wavelength across (k a <= pi/2: no geometric shadow; a listener farther from them
/// than their period squared over the wavelength is assumed). Such a
/// body scatters weakly (a slat 1 cm thick 1 cm beside the line of sight read 10 dB below the free
/// field at 63 Hz, its near edge taken for a screen's), while the first-order edge sum round it can
/// fall far short. The thin bodies beside them go with them. Per band, 1/m^2; 0 where no such floor
/// holds.
Bands thinBodiesFloor(const std::vector<EdgePath>& paths, const DirectSound& coherent,
                      const Bands& free, BoundQuery& q);

}  // namespace dpc
