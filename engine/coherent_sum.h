// The coherent sum of the direct sound and the first-order edge and slit paths
// (engine/diffraction.h): |p|^2 averaged over each octave band's kDiffractionFrequenciesPerBand
// frequencies, each path's UTD coefficient at the band's anchors and interpolated between, the
// slits' fields coupled by their mutual loading (engine/slit.h).
//
// Internal to the engine. Any thread; allocates its scratch; no errors.
#pragma once

#include <vector>

#include "common/bands.h"
#include "engine/edge_path.h"
#include "engine/propagation.h"
#include "scene/directivity.h"

namespace dpc {

/// The slit whose gap the line of sight from source to L passes through, if any: an owner
/// path's gap (from its edge across `mouth` for gapWidth, along the edge where the gap runs:
/// the slit's extent) that the segment crosses. That slit's field is then the direct sound's own at the frequencies where
/// the slit model holds (engine/slit.h: it is driven by the incident pressure at its mouth).
const EdgePath* slitOnLineOfSight(const std::vector<EdgePath>& paths, const glm::vec3& source,
                                  const glm::vec3& L);

/// Per path, the source's energy weight toward its edge point Q (scene/directivity.h); empty
/// for an omni source.
std::vector<Bands> leavingWeights(const std::vector<EdgePath>& paths, const Directivity& d,
                                  const glm::vec3& forward);

/// The largest pressure amplitude (the direct sound's scale, 1/r) path p's UTD field takes in
/// band b: at the band's lowest frequency, where |D| / sqrt(k) is largest; air and the
/// source's weight left out.
double bandAmplitude(const EdgePath& p, int b, float speedOfSound);

/// Band intensity (1/m^2, the scale of 1/(4 pi r^2)) of the coherent sum of the direct sound
/// (when visible; its directivity weight is already in direct.intensity) and the edge paths,
/// each path's pressure scaled by the square root of its energy weight (none when empty);
/// throughSlit: the slit the line of sight passes (slitOnLineOfSight), or null. Only the
/// first `bands` bands are summed (the rest 0).
Bands coherentIntensity(const std::vector<EdgePath>& paths, const DirectSound& direct,
                        const EdgePath* throughSlit, float speedOfSound, const Bands& airPerMetre,
                        const std::vector<Bands>& weights, int bands = kNumBands);

}  // namespace dpc
