// Interaural coherence of a binaural late field made from K directions, matched per octave
// band to the diffuse-field coherence of the HRTF set in use.
//
// The spatial synthesiser renders the late field as K independent noises, each through one
// direction's HRIR pair (synthesis/spatial_synthesizer.h). Its ears' coherence in band b is
// then rho_K = Re sum_d H_L,d H_R,d* / sqrt(sum_d |H_L,d|^2 sum_d |H_R,d|^2) (summed over the
// band's bins too), which with K = 8 stays far from a diffuse field's: the field of all
// directions, rho_t, which the same formula gives over a dense, even set of directions
// (uniformSpatialDirections, each through the exact HRTF filter). Listeners hear interaural
// coherence as a room's width and envelopment (ISO 3382-1 Annex B's IACC).
//
// The match mixes each band's two ear signals per frame, before the direct sound and the
// exact early paths are added (they keep their own HRIRs). The K directions' coherence is
// that of the frame's late field: rho_K = sum_d E_d C_d / sqrt(sum_d E_d L_d sum_d E_d R_d),
// E_d the frame's band energy from direction d and C_d, L_d, R_d its HRIR pair's cross and
// ear powers in the band. With l and r the ears normalised to unit power and X = l + r,
// Y = l - r (uncorrelated, of power 2 (1 +- rho_K)), L' = sqrt(P_L) (a X + c Y),
// R' = sqrt(P_R) (a X - c Y) with a = sqrt((1 + rho_t) / (4 (1 + rho_K))),
// c = sqrt((1 - rho_t) / (4 (1 - rho_K))) keeps each ear's power and gives coherence rho_t
// (the covariance-domain mixing of Vilkamo, Bäckström and Kuntz, "Optimized covariance
// domain framework for time-frequency processing of spatial audio", JAES 61, 2013, for two
// channels and a real target). As gains on the band's ear signals:
//   L' = (a + c) L + (a - c) sqrt(P_L / P_R) R,  R' = (a - c) sqrt(P_R / P_L) L + (a + c) R.
// Each ear keeps its power exactly when the band's actual coherence is rho_K; the step from
// rho_K towards rho_t is held to 1 - rho_K^2, so that an error e in rho_K changes an ear's
// power by at most a factor 1 +- e (a late field from one or two directions is matched only
// part of the way).
#pragma once

#include <array>
#include <functional>
#include <span>
#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"

namespace dpc {

struct DirectionFilter;

/// One band's 2 x 2 mix: out[c] = same[c] x in[c] + other[c] x in[1 - c].
struct EarMix {
  std::array<float, 2> same{1.f, 1.f};
  std::array<float, 2> other{0.f, 0.f};
};

/// A band's sums over the bins of its octave: Re H_L H_R*, |H_L|^2, |H_R|^2.
struct EarPowers {
  double cross = 0.0, left = 0.0, right = 0.0;
  /// Re H_L H_R* / sqrt(|H_L|^2 |H_R|^2); 0 without power.
  double coherence() const;
};

/// Directions over the sphere that stand for a diffuse field in the coherence target.
inline constexpr int kDiffuseCoherenceDirections = 1024;

class CoherenceMatch {
 public:
  CoherenceMatch() = default;
  /// For K directions' two-channel `filters` (left, right) and the exact filter of any
  /// listener-frame direction, matched from band `fromBand` on (the bands below are left as
  /// they are). sampleRate Hz. Construction time (control or propagation thread): calls
  /// `exact` kDiffuseCoherenceDirections times, allocates, plans FFTs of 8192 points or more.
  /// Throws std::invalid_argument unless every filter has two channels.
  CoherenceMatch(const std::vector<DirectionFilter>& filters,
                 const std::function<void(const glm::vec3&, DirectionFilter&)>& exact,
                 int sampleRate, int fromBand);

  /// rho_t: the HRTF set's diffuse-field coherence in band b.
  double diffuse(int b) const { return diffuse_[size_t(b)].coherence(); }
  /// The K directions' coherence in band b for direction energies energy[d] (any unit).
  double directions(int b, std::span<const double> energy) const;
  /// Band b's mix for direction energies energy[d]; identity below fromBand, without energy,
  /// or where the directions' or the target coherence is too close to +-1. No allocation.
  EarMix mix(int b, std::span<const double> energy) const;

 private:
  EarPowers weighted(int b, std::span<const double> energy) const;
  int fromBand_ = kNumBands;
  std::vector<std::array<EarPowers, kNumBands>> perDirection_;
  std::array<EarPowers, kNumBands> diffuse_{};
};

}  // namespace dpc
