// The magnitude-least-squares (MagLS) binaural decoder of an AmbiX (ACN, SN3D) signal:
// C. Schörkhuber, M. Zaunschirm, R. Höldrich, "Binaural rendering of Ambisonic signals via
// magnitude least squares", DAGA 2018; F. Zotter, M. Frank, "Ambisonics", Springer 2019,
// sec. 4.11. Optionally with the diffuse-field covariance constraint of M. Zaunschirm,
// C. Schörkhuber, R. Höldrich, "Binaural rendering of Ambisonic signals by head-related impulse
// response time alignment and a diffuseness constraint", JASA 143(6), 2018.
//
// The decoder is (N + 1)^2 x 2 filters h_c,ear(f) such that a plane wave from s, encoded as
// b_c = Y_c(s), reaches the ears as sum_c h_c(f) Y_c(s). It is fitted to the SOFA set's own
// measurements H_q(f) (directions u_q, Q of them; Hrtf::measurement) on an fftSize-point
// frequency grid, per ear:
//  - below the cut-off f_c (kMagLsCutoffHz): weighted, regularised least squares of the
//    complex HRTF,
//      h(f) = argmin sum_q w_q |y_q^T h - H_q(f)|^2 + lambda |h|^2,
//    y_q the orthonormal (N3D) harmonics of u_q, w_q the measurement's share of the sphere (its
//    Voronoi cell over 4 pi, cut at the set's coarsest spacing: common/sphere_quadrature.h),
//    lambda = kMagLsRegularisation. The weights make the sum the discretised integral over the
//    sphere, so a densely measured ring does not outweigh a sparse one. Where the set has no
//    measurement (KEMAR below -50 degrees: 11.7 % of the sphere) least squares is free to grow
//    (+30 dB straight down at order 7); there the fit takes what per-path binaural plays, the
//    HRTF grid's blend of the nearest measurements (Hrtf::hrir), at the points of a 4000-point
//    Fibonacci lattice that lie in the gap, sharing its area, so that both renderers agree
//    there and the least squares is over the whole sphere.
//  - from f_c up: magnitude least squares by the paper's phase retrieval: at bin k the target
//    is |H_q(f_k)| exp(i arg(y_q^T h(f_(k-1)))), the measured magnitude with the phase the
//    decoder gave that direction one bin lower, fitted by the same least squares. Above the
//    order's spatial band limit a decoder cannot match magnitude and phase; the ears' levels
//    (the ILD, the timbre) are what is heard there, the interaural phase is not. Here each
//    direction's weight, per ear, is w_q (E / E_q)^alpha, E_q the ear's power at u_q summed
//    from f_c up and E its weighted mean (alpha = kMagLsLevelWeightExponent): the plain
//    magnitude error weighs a shadowed ear's 20 dB quieter directions a hundred times less than
//    the lit ones, although the ILD, a ratio, hears their error alike; alpha = 1 would weigh
//    relative errors alike. The measurements' weights are rescaled to keep their share of the
//    sphere; the filled gap keeps its plain weights, and order 1 uses alpha = 0
//    (a first-order field cannot shape the shadow; its 2 and 4 kHz mean ILD errors grew with
//    alpha = 1/4).
// The phase retrieval continues each direction's phase from f_c with zero group delay, so the
// spectra are first advanced by the set's bulk delay tau (the mean phase step of its
// direction-averaged response over kMagLsDelayBandHz, both ears; 45 samples, 0.95 ms, for KEMAR
// at 48 kHz) and delayed again after the fit by tau plus kMagLsPreDelaySeconds: the high band
// then lands where the HRIRs' own energy is, with room before it for its pre-ringing, instead
// of wrapping around time zero. Below f_c the advance changes nothing (least squares is
// linear); above, it is the phase continuation with tau's phase step per bin.
// Covariance constraint (MagLsOptions::covarianceMaxOrder; from the lower of f_c and the
// order's spatial band limit f_N = N c / (2 pi r), r = kMagLsHeadRadius, up): the 2 x 2
// interaural covariance of an isotropic diffuse field through the decoder,
// R^ = sum_q w_q d_q^H d_q (d_q = [left right] decoded at u_q), is matched to the HRTF set's,
// R = sum_q w_q H_q^H H_q, by h <- h M, M = R^^(-1/2) P R^(1/2) with P the unitary polar
// factor of (R^(1/2) R^^(1/2))^H: the matching matrix closest to the identity (Vilkamo,
// Bäckström, Kuntz, JAES 61(6), 2013). It restores the diffuse field's interaural coherence,
// which MagLS alone raises (most at low orders), but it mixes the ears and so changes direct
// sounds' ILD; on by default at orders 1 and 2 (kMagLsCovarianceMaxOrder; docs/spatial.md
// gives both). Below f_c it starts at f_N, where an order-N decoder stops following the
// complex HRTF: order 1's least-squares band (f_N = 624 Hz) leaves a diffuse field's ears at
// -0.22 at 1 kHz against KEMAR's -0.03 (real part over the octave).
// Finally the N3D coefficients become SN3D ones (times sqrt(2n + 1)), and each filter is
// brought to the time domain and cut to `length` taps, the last kMagLsFadeFraction faded out
// with a raised cosine.
//
// Construction only (control thread): allocates about Q x fftSize x 8 bytes (19 MB for KEMAR's
// 710 measurements and 470 gap points at fftSize 2048), plans FFTW; 0.17-0.2 s at orders 1 to
// 5, 0.27 s at order 7 for KEMAR.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "audio/hrtf.h"

namespace dpc::audio {

/// Tikhonov loading lambda of the least-squares fit, relative to a complete sphere's Gram
/// matrix (the identity). With the unmeasured region filled the Gram matrix is close to the
/// identity and lambda only guards the solve: from 1e-6 to 1e-2 it changed no ILD by 0.1 dB.
inline constexpr double kMagLsRegularisation = 1e-3;

/// Share of each filter's taps faded out at its end (raised cosine).
inline constexpr double kMagLsFadeFraction = 0.25;

/// The band, Hz, whose mean phase step gives the set's bulk delay: above the measurement's
/// low-frequency roll-off (KEMAR's group delay is 3.5 ms at 125-250 Hz), below the
/// frequencies where directions add up incoherently.
inline constexpr double kMagLsDelayBandHz[2] = {500.0, 2000.0};

/// Room left before the bulk delay, s: the MagLS band's response starts up to about 1 ms
/// before it (the step from least squares to MagLS at f_c rings both ways).
inline constexpr double kMagLsPreDelaySeconds = 0.5e-3;

/// The cut-off f_c, Hz, at every order: below it the interaural time difference is the
/// dominant lateralisation cue (the duplex theory; Blauert, "Spatial Hearing", 1997, sec. 2.4),
/// carried by the interaural phase that only least squares keeps; above it least squares
/// misses KEMAR's ILD by more than MagLS does, even where kr < N (docs/spatial.md, "Binaural
/// decoding": the cut-off).
inline constexpr double kMagLsCutoffHz = 1500.0;

/// alpha, the exponent of the MagLS band's level weights at orders 2 and up (see the file
/// comment). A trade-off, measured at order 3 (docs/spatial.md, "Binaural decoding"): the mean
/// |ILD error| over 96 directions falls as alpha grows (2, 4 and 8 kHz summed: 3.40 dB at 0,
/// 3.14 at 1/4, 3.10 at 1/2, 3.00 at 1), while at the side, where KEMAR's 4 kHz ILD dips (the
/// contralateral bright spot, narrower than an order-3 field resolves), the decoder overshoots
/// it more (90 degrees against per-path binaural: +1.6 dB at 1/4, +2.0 at 1/2, +3.3 at 1).
inline constexpr double kMagLsLevelWeightExponent = 0.25;

/// The head radius, m, of the spatial band limit f_N = N c / (2 pi r) (kr = N; the spherical
/// head of Woodworth's ITD formula), from which the covariance constraint applies below f_c.
inline constexpr double kMagLsHeadRadius = 0.0875;

/// Speed of sound, m/s, of the spatial band limit (20 degrees C).
inline constexpr double kMagLsSpeedOfSound = 343.0;

/// The highest order whose decoder applies the covariance constraint by default. MagLS alone
/// gives a diffuse field's ears a coherence (real part over each octave) of 0.65 / 0.58 at
/// 2 / 4 kHz at order 1 and 0.33 / 0.46 at order 2 (KEMAR's: 0.0), which listeners hear as a
/// narrow late field; the constraint's price, the direct sound's mean |ILD error| at 2 / 4 /
/// 8 kHz, is +2.4 / +1.5 / +1.2 dB at order 1 and +0.5 / +1.2 / +1.7 dB at order 2
/// (docs/spatial.md, "Binaural decoding"). At order 3 MagLS leaves 0.09 / 0.21 at 4 / 8 kHz,
/// and the constraint would add 1.1 dB to the 8 kHz error, so it stays off from order 3 up.
inline constexpr int kMagLsCovarianceMaxOrder = 2;

struct MagLsOptions {
  double cutoffHz = kMagLsCutoffHz;  ///< least squares below, MagLS from here on
  /// Zaunschirm et al.'s constraint at orders up to this one (0: never; kMaxAmbisonicOrder:
  /// always), from min(f_c, f_N) on.
  int covarianceMaxOrder = kMagLsCovarianceMaxOrder;
  /// alpha from order 2 up (order 1: 0); 0 (or any value not above 0) gives the paper's weights
  double levelWeightExponent = kMagLsLevelWeightExponent;
};

/// Where the covariance constraint starts at `order`, Hz: min(f_c, f_N) (see the file comment).
double magLsCovarianceFromHz(int order, const MagLsOptions& options);

/// Per ACN channel, per ear (0 left, 1 right): a filter of `length` taps.
using ChannelEarFilters = std::vector<std::array<std::vector<float>, 2>>;

/// The MagLS decoder of `order` (1 .. kMaxAmbisonicOrder) for `hrtf`'s measurements at its
/// sample rate, filters of `length` taps (at least the HRIR length). Throws
/// std::invalid_argument when the set has fewer measurements than channels.
ChannelEarFilters magLsFilters(int order, const Hrtf& hrtf, const MagLsOptions& options,
                               size_t length);

}  // namespace dpc::audio
