// The magnitude-least-squares (MagLS) binaural decoder of an AmbiX (ACN, SN3D) signal:
// C. Schörkhuber, M. Zaunschirm, R. Höldrich, "Binaural rendering of Ambisonic signals via
// magnitude least squares", DAGA 2018; F. Zotter, M. Frank, "Ambisonics", Springer 2019,
// sec. 4.11. With the diffuse-field covariance constraint of M. Zaunschirm, C. Schörkhuber,
// R. Höldrich, "Binaural rendering of Ambisonic signals by head-related impulse response time
// alignment and a diffuseness constraint", JASA 143(6), 2018, sec. III.B.
//
// The decoder is (N + 1)^2 x 2 filters h_c,ear(f) such that a plane wave from s, encoded as
// b_c = Y_c(s), reaches the ears as sum_c h_c(f) Y_c(s). It is fitted to the SOFA set's own
// measurements H_q(f) (directions u_q, Q of them; Hrtf::measurement), on an fftSize-point
// frequency grid, per ear:
//  - below the cut-off f_c = N c / (2 pi r) (kr = N: the highest frequency an order-N sound
//    field reproduces on a head of radius r = kHeadRadiusMetres; 624 Hz, 1.87 kHz, 3.12 kHz
//    at orders 1, 3, 5): weighted, regularised least squares of the complex HRTF,
//      h(f) = argmin sum_q w_q |y_q^T h - H_q(f)|^2 + lambda |h|^2
//    (y_q the orthonormal, N3D, harmonics; w_q the measurement's share of the sphere, its
//    Voronoi cell, cut at the set's coarsest spacing, common/sphere_quadrature.h; lambda =
//    kMagLsRegularisation). The weights make the sum the discretised integral over the
//    sphere, so a ring measured densely does not outweigh one measured sparsely; the cells'
//    cut and lambda keep the fit bounded where the set has no measurement (KEMAR below -40
//    degrees elevation: 15 % of the sphere), where least squares alone is free to grow.
//  - from f_c up: magnitude least squares by the paper's phase retrieval: at bin k the
//    target is |H_q(f_k)| exp(i arg(y_q^T h(f_(k-1)))), the measured magnitude with the phase
//    the decoder itself gave that direction one bin lower, solved by the same least squares.
//    Above kr = N an order-N decoder cannot match both magnitude and phase; the ears' levels
//    (hence the ILD and the timbre) are what is heard there, the interaural phase is not.
// The phase retrieval continues each direction's phase from f_c with zero group delay, so the
// spectra are first advanced by the set's bulk delay tau (the group delay of its
// direction-averaged response between f_c / 2 and f_c, both ears; 1.1 ms for KEMAR at 48
// kHz) and delayed by it again after the fit: the high band then lands where the HRIRs' own
// energy is, not wrapped around time zero. Below f_c this changes nothing (least squares is
// linear); above, it is the phase continuation with tau's phase advance per bin.
// Covariance constraint (optional, on by default, from f_c up): the 2 x 2 interaural
// covariance of an isotropic diffuse field through the decoder, R^ = sum_q w_q d_q^H d_q (d_q
// the decoded row [left right] at u_q), is matched to the HRTF set's, R = sum_q w_q H_q^H H_q,
// by h <- h M with M = R^^(-1/2) P R^(1/2), P the unitary polar factor of (R^(1/2) R^^(1/2))^H
// (the matrix closest to the identity that matches, Vilkamo, Bäckström, Kuntz, JAES 61(6),
// 2013): both ears keep the diffuse field's power and interaural coherence, which MagLS alone
// lowers (Zaunschirm et al.: most at low orders).
// Finally the N3D coefficients become SN3D ones (times sqrt(2n + 1)), each filter is brought to
// the time domain and cut to `length` taps with a raised-cosine fade over its last
// kMagLsFadeFraction.
//
// Construction only (control thread): allocates about Q x fftSize x 16 bytes (12 MB for
// KEMAR at fftSize 2048), plans FFTW, costs O(Q (N + 1)^2 fftSize) (0.2 s at order 3).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "audio/hrtf.h"

namespace dpc::audio {

/// Head radius, m, of the cut-off kr = N (Woodworth's spherical head for KEMAR, as in
/// tests/audio/hrtf_test.cpp), and the speed of sound, m/s, it is taken with.
inline constexpr double kHeadRadiusMetres = 0.0875;
inline constexpr double kHeadSpeedOfSound = 343.0;

/// Tikhonov loading lambda of the least-squares fit, relative to a complete sphere's Gram
/// matrix (the identity): see docs/spatial.md, "Binaural decoding", for how it was chosen.
inline constexpr double kMagLsRegularisation = 1e-2;

/// Share of each filter's taps faded out at its end (raised cosine).
inline constexpr double kMagLsFadeFraction = 0.25;

/// The band, Hz, whose mean phase step gives the set's bulk delay: above the measurement's
/// low-frequency roll-off (KEMAR's group delay is 3.5 ms at 125-250 Hz), below the
/// frequencies where directions add up incoherently.
inline constexpr double kMagLsDelayBandHz[2] = {500.0, 2000.0};

/// Room left before the bulk delay, s: the MagLS band's response starts up to about 1 ms
/// before it (the step from least squares to MagLS at f_c rings both ways).
inline constexpr double kMagLsPreDelaySeconds = 0.5e-3;

/// The lowest cut-off, Hz: below it the interaural time difference is the dominant
/// lateralisation cue (the duplex theory; Blauert, "Spatial Hearing", 1997, sec. 2.4), carried
/// by the interaural phase that only the least-squares part keeps.
inline constexpr double kMagLsMinCutoffHz = 1500.0;

/// The cut-off f_c = max(N c / (2 pi r), kMagLsMinCutoffHz), Hz: N c / (2 pi r) is the frequency
/// up to which an order-N sound field reproduces the HRTF of a head of radius
/// kHeadRadiusMetres (kr <= N): 624 Hz, 1.87 kHz, 3.12 kHz at orders 1, 3, 5.
double magLsCutoffHz(int order);

struct MagLsOptions {
  double cutoffHz = 0.0;            ///< least squares below, MagLS from here; 0: magLsCutoffHz
  bool covarianceConstraint = false;  ///< Zaunschirm et al.'s diffuse-field constraint above f_c
};

/// Per ACN channel, per ear (0 left, 1 right): a filter of `length` taps.
using ChannelEarFilters = std::vector<std::array<std::vector<float>, 2>>;

/// The MagLS decoder of `order` (1 .. kMaxAmbisonicOrder) for `hrtf`'s measurements at its
/// sample rate, filters of `length` taps (at least the HRIR length). Throws
/// std::invalid_argument when the set has fewer measurements than channels.
ChannelEarFilters magLsFilters(int order, const Hrtf& hrtf, const MagLsOptions& options,
                               size_t length);

}  // namespace dpc::audio
