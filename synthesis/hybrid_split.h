// Hybrid rendering's split of a source's response into an early part, rendered per source,
// and a late part, rendered once per cluster of sources through a shared late bus.
//
// The early part keeps everything that tells sources apart: the direct sound, the exact early
// paths and the first reflections, at their delays and directions. After the split time the
// field of a room is diffuse: its decay and direction distribution depend on the room far
// more than on the source, so sources can share one late impulse response scaled per source
// (Schissler & Manocha, "Interactive Sound Propagation and Rendering for Large Multi-Source
// Scenes", ACM TOG 36(1), 2016, section 6: early per source, late per cluster; Jot, Cerveau &
// Warusfel 1997 for the early/late model).
//
// The split is energy-complementary: over the fade [split - fade, split) the early part's bins
// carry w(t) of each bin's energy, w falling linearly from 1 to 0, and the late part 1 - w. The
// two are independent noise realisations, so their energies add: early + late = the response,
// bin by bin, within float rounding. Arrivals placed exactly (direct sound, exact paths) at or
// after split - fade go into the late part's bins as energy (with their direction), counted.
//
// Threads: the propagation thread; no allocation once the outputs have the inputs' sizes
// (copy assignment reuses their storage). No errors.
#pragma once

#include <span>
#include <vector>

#include "engine/energy_response.h"
#include "engine/propagation.h"
#include "engine/specular_paths.h"

namespace dpc {

struct HybridSplit {
  double splitSeconds = 0.1;  ///< where the early part has ended (its weight is 0)
  double fadeSeconds = 0.01;  ///< length of the energy-complementary crossfade before it
  /// Energy weight of the early part for a bin starting at t seconds (1, the fade, then 0).
  double earlyWeight(double t) const;
  /// Whether an exact arrival at t seconds stays in the early part (before the fade starts).
  bool arrivalIsEarly(double t) const { return t < splitSeconds - fadeSeconds; }
  /// Whether the direct sound goes to the late part (visible, and not early).
  bool directIsLate(const DirectSound& d) const {
    return d.visible && !arrivalIsEarly(d.delaySeconds);
  }
};

/// Early length of hybrid rendering for a scene: the longest direct path that fits in its
/// bounds (diagonal / c) plus kHybridEarlySeconds, plus the fade; at most irLength. Seconds.
double hybridEarlyLength(double boundsDiagonalMetres, double speedOfSound, double irLength,
                         double fadeSeconds);
/// Reflections per source kept after the longest direct path (the early reflections within
/// which a listener hears the source's position and the room's shape).
inline constexpr double kHybridEarlySeconds = 0.08;
/// The crossfade between the early and late parts.
inline constexpr double kHybridFadeSeconds = 0.01;

/// One source's late part and what went into it.
struct LateShare {
  double energy = 0.0;       ///< broadband late energy (sum over bins and bands), 1/m^2
  int lateArrivals = 0;      ///< exact arrivals (direct sound included) moved to the late part
  bool directIsLate = false;  ///< the direct sound arrived after the early part
};

/// Keeps r's early part in place (bins times earlyWeight). Mono responses.
void keepEarly(EnergyResponse& r, const HybridSplit& split);
void keepEarly(DirectionalEnergyResponse& r, const HybridSplit& split);

/// Adds r's late part (bins times 1 - earlyWeight) into `late` (same bin width and length),
/// with the exact arrivals that fall after the early part (direct when visible, then `early`).
/// Returns the source's late share. Mono and directional forms.
LateShare addLate(const EnergyResponse& r, const DirectSound& direct,
                  std::span<const SpecularPath> early, const HybridSplit& split,
                  EnergyResponse& late);
LateShare addLate(const DirectionalEnergyResponse& r, const DirectSound& direct,
                  std::span<const SpecularPath> early, const HybridSplit& split,
                  DirectionalEnergyResponse& late);

/// The exact paths of `all` that stay in the early part, into `out` (cleared first; no
/// allocation within its capacity).
void earlyPaths(std::span<const SpecularPath> all, const HybridSplit& split,
                std::vector<SpecularPath>& out);

}  // namespace dpc
