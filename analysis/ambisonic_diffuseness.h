// Diffuseness of an Ambisonic (AmbiX: ACN order, SN3D) impulse response's late part, per
// octave band and broadband, by two standard measures:
//   - DirAC's, from the first-order channels (Pulkki, "Spatial sound reproduction with
//     directional audio coding", JAES 55, 2007): psi = 1 - |sum W v| / sum (W^2 + |v|^2) / 2,
//     v = (X, Y, Z) (ACN 3, 1, 2); 0 for one plane wave, 1 for a diffuse field.
//   - COMEDIE's, from every order's channels (Epain and Jin, "Spherical harmonic signal
//     covariance and sound field diffuseness", IEEE/ACM TASLP 24, 2016): with lambda_i the
//     M = (N + 1)^2 eigenvalues of the channels' covariance in N3D normalisation (SN3D order n
//     times sqrt(2 n + 1)) and lambda their mean, psi = 1 - sum |lambda_i - lambda| /
//     (2 (M - 1) lambda); 0 for one plane wave, 1 for a field whose covariance is that of a
//     diffuse one. It also falls below 1 when fewer than M independent directions make the
//     field, which first order cannot see.
// The late part is [t0 + 80 ms, end) with t0 W's first sample within 20 dB of its squared peak
// (as analysis/interaural_correlation.h); the bands through the IEC 61260-1 filters of the
// room parameters. A finite record biases both slightly below 1 for a diffuse field (the
// covariance estimated from B T independent samples per band). Threads: any thread but the
// audio thread; allocates O(M n); no errors thrown (NaN where a band cannot be analysed).
#pragma once

#include <array>
#include <cstddef>
#include <span>

#include "common/bands.h"

namespace dpc::audio {

/// Boundary between the early and the late part, seconds after t0 (ISO 3382-1).
inline constexpr double kDiffusenessLateSeconds = 0.080;

struct AmbisonicDiffuseness {
  std::array<double, kNumBands> dirac;    ///< per octave band; NaN above Nyquist or silent
  std::array<double, kNumBands> comedie;  ///< the same
  double broadbandDirac;
  double broadbandComedie;
  double onsetSeconds;  ///< t0 from the first sample; NaN when W holds no energy
};

/// channels: (order + 1)^2 AmbiX channels of n samples at sampleRate Hz; order >= 1.
AmbisonicDiffuseness analyzeAmbisonicDiffuseness(std::span<const float* const> channels,
                                                 int order, size_t n, int sampleRate);

}  // namespace dpc::audio
