// Real spherical harmonics in the AmbiX convention: ACN channel order, SN3D normalisation.
//
// Direction: the listener frame of audio/hrtf.h (x forward, y left, z up), azimuth
// phi = atan2(y, x) (counter-clockwise, 0 straight ahead), elevation theta = asin(z) (up
// positive). For order n = 0..N and degree m = -n..n, channel ACN = n^2 + n + m carries
//   Y_n^m(phi, theta) = N_n^|m| P_n^|m|(sin theta) x { cos(m phi)    for m >= 0
//                                                     { sin(|m| phi) for m < 0,
//   N_n^|m| = sqrt((2 - delta_m0) (n - |m|)! / (n + |m|)!)        (SN3D),
// with P_n^m the associated Legendre functions WITHOUT the Condon-Shortley phase (-1)^m.
// So Y_0^0 = 1 (W carries the pressure), Y_1^-1 = y, Y_1^0 = z, Y_1^1 = x for a unit vector,
// and sum_m Y_n^m(u) Y_n^m(v) = P_n(u . v) for every order n (the addition theorem in SN3D).
// Sources: C. Nachbar, F. Zotter, E. Deleflie, A. Sontacchi, "ambiX - a suggested Ambisonics
// format", Ambisonics Symposium 2011 (ACN, SN3D); F. Zotter, M. Frank, "Ambisonics",
// Springer 2019, ch. 4 (real spherical harmonics).
//
// max-rE weights (Zotter & Frank 2019, ch. 4; Zotter & Frank, "All-round ambisonic
// panning and decoding", JAES 60(10), 2012): a_n = P_n(r_E) with r_E the largest root of
// P_{N+1}; the energy vector of a plane wave decoded with these weights then has the length
// r_E, the largest reachable at order N.
//
// Pure functions; any thread, including the audio thread: no allocation, no locks, no
// exceptions (orders outside 1..kMaxAmbisonicOrder are the caller's error, clamped).
#pragma once

#include <array>
#include <cstddef>
#include <span>

namespace dpc {

/// Highest Ambisonic order dpc renders: 64 channels; AmbiX tools (IEM, ambiX plug-ins) stop at 7.
inline constexpr int kMaxAmbisonicOrder = 7;

/// (order + 1)^2: the channels of a full-sphere signal of that order.
constexpr int ambisonicChannels(int order) { return (order + 1) * (order + 1); }

/// The ACN/SN3D real spherical harmonics of `dir` (need not be unit length; a zero or
/// non-finite vector counts as straight ahead) up to `order` (0 .. kMaxAmbisonicOrder) into
/// out[0 .. ambisonicChannels(order) - 1], dimensionless.
void sphericalHarmonicsSn3d(int order, const float dir[3], std::span<float> out);

/// The same harmonics up to order 1 (out[0 .. 3]) without trigonometry: (1, y, z, x) of the
/// unit vector along `dir` (a zero or non-finite vector: straight ahead), which is what the
/// definition above gives at order 1; equal to sphericalHarmonicsSn3d(1, ...) to float
/// rounding, about 15 times cheaper (per-arrival use: a bake's SH energy).
void sphericalHarmonicsSn3dFirstOrder(const float dir[3], std::span<float> out);

/// The per-order max-rE weights a_0 .. a_order (a_0 = 1) into out[0 .. order].
void maxReWeights(int order, std::span<float> out);

/// r_E of max-rE at `order`: the largest root of the Legendre polynomial P_{order+1}.
double maxReRadius(int order);

/// The Legendre polynomial P_n(x), n >= 0.
double legendre(int n, double x);

/// Node k (0 = the largest) of the n-point Gauss-Legendre rule on [-1, 1] and its weight:
/// Newton on P_n from cos(pi (k + 0.75) / (n + 0.5)) (Abramowitz & Stegun 22.16.6), n >= 1.
void gaussLegendreNode(int n, int k, double& x, double& w);

/// A rotation in the listener frame: 3 x 3, row-major, orthonormal with determinant 1.
using Rotation3 = std::array<float, 9>;

/// The (N+1)^2 x (N+1)^2 matrix (row-major) that rotates an order-N AmbiX sound field by
/// `r`: a plane wave encoded from s becomes the one encoded from r s, M Y(s) = Y(r s). It is
/// block diagonal (order n couples only with order n) and each block is orthogonal (SN3D
/// scales a whole block by one constant). Computed by projection onto the harmonics over a
/// Gauss-Legendre (N + 1 nodes) x equiangular (2N + 1) quadrature, exact for the degree-2N
/// products: M_ij = (2n + 1) / (4 pi) sum_k w_k Y_i(r u_k) Y_j(u_k) (SN3D: the integral of
/// Y_n^m squared over the sphere is 4 pi / (2n + 1); Zotter & Frank 2019, ch. 4).
/// Writes ambisonicChannels(order)^2 floats; no allocation; any thread (the audio thread may
/// call it per block: (N + 1)(2N + 1) harmonic evaluations and sum_n (2n+1)^2 products each).
void ambisonicRotation(int order, const Rotation3& r, std::span<float> out);

/// Applies `m` (ambisonicRotation's layout) in place to `frames` samples of the
/// ambisonicChannels(order) planar channels. No allocation; any thread, the audio thread too.
void rotateAmbisonic(int order, std::span<const float> m, float* const* channels, size_t frames);

}  // namespace dpc
