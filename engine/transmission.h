// Sound through surfaces: the choice a ray makes at a transmitting surface, and the direct path
// through the surfaces between two points. Materials give the energy transmission coefficient
// tau = 10^(-R/10) per octave band (scene/transmission.h); the absorption coefficient alpha
// counts the transmitted part as absorbed (Sabine's alpha for the source room), so at a surface
// reflected = 1 - alpha, transmitted = tau, dissipated = alpha - tau (docs/estimators.md,
// "Transmission").
//
// A partition is one surface: R is the whole partition's, counted at each surface a path
// crosses, so a partition is modelled as one (double-sided) sheet, not as a closed slab whose two
// faces would count R twice. Coincident double-sided faces count once (a crossing continues past
// the surface by an offset, so the twin face lies behind it).
//
// Threads: any (pure functions and tracer queries); no allocation; no errors.
#pragma once

#include <glm/vec3.hpp>

#include "common/bands.h"
#include "engine/geometry.h"
#include "engine/tracer.h"

namespace dpc {

/// Smallest probability of passing through a transmitting surface (see transmissionProbability).
inline constexpr float kMinTransmissionProbability = 0.3f;

/// Probability p that a ray carrying band energies `energy` passes through a surface of
/// reflectance (1 - alpha) and transmittance tau: the energy-weighted share of the transmitted
/// part, sum E tau / sum E (tau + 1 - alpha), raised to kMinTransmissionProbability (so that
/// enough rays reach the receiving room to keep its estimate's variance down: a partition of
/// R = 30 dB would otherwise pass one ray in a thousand hits; docs/estimators.md gives the
/// measured trade-off); 0 when no band of the ray is transmitted, 1 when nothing is reflected.
float transmissionProbability(const Bands& energy, const Bands& reflectance, const Bands& tau);

/// The Monte Carlo choice at a transmitting surface: with u uniform in [0, 1), passes through
/// when u < p (transmissionProbability), weighting energy by tau / p, else reflects, weighting it
/// by (1 - alpha) / (1 - p): both branches' expected energies are the physical ones, so the
/// estimator is unbiased. Returns true for the pass-through.
bool chooseTransmission(const Bands& reflectance, const Bands& tau, float u, Bands& energy);

/// What the straight path between two points crosses: the product of the transmittances of the
/// surfaces on it (1 in every band for a free path), how many it crossed, and whether it is
/// blocked (an opaque surface, or more than maxCrossings transmitting ones: `capped`).
struct PathTransmission {
  Bands tau{1.f};
  int crossings = 0;
  bool blocked = false;
  bool capped = false;  ///< blocked because the crossing bound was reached (count and report)
};

/// Most surfaces the direct path crosses before it counts as blocked (PathTransmission::capped).
inline constexpr int kMaxDirectCrossings = 16;

/// Walks the segment from `from` along unit `dir` for `length` metres with repeated closest-hit
/// queries, each starting surfaceOffset() past the previous hit. Any thread.
PathTransmission transmissionAlong(const Tracer& tracer, const Geometry& geometry,
                                   const glm::vec3& from, const glm::vec3& dir, float length,
                                   int maxCrossings = kMaxDirectCrossings);

}  // namespace dpc
