// The uniform theory of diffraction's (UTD) hard-wedge coefficient (R. G. Kouyoumjian &
// P. H. Pathak, "A uniform geometrical theory of diffraction for an edge in a perfectly
// conducting surface", Proc. IEEE 62(11), 1974, eqs. 25-27; the acoustically hard wedge takes
// the sum of the four terms) and the Fresnel integral it is built on. engine/diffraction.h
// sums the edge paths; engine/slit.h integrates a slit's line source with fresnelIntegral.
//
// Convention: time factor e^{+j omega t}, so a path of length l carries e^{-jkl}. Angles in
// radians, lengths in metres, k in rad/m. Threads: any (the transition function's table is
// built once, on first use, by a thread-safe static). No allocation after that; no errors.
#pragma once

#include <array>
#include <complex>

namespace dpc {

/// A complex number as plain data (real, imaginary), for interfaces that avoid std::complex.
struct Complex {
  double re = 0.0, im = 0.0;
};

/// The transition function F(X) = 2j sqrt(X) e^{jX} int_sqrt(X)^inf e^{-jt^2} dt, X >= 0
/// (negative X is read as 0), within 2e-5 absolute everywhere: a cubic Hermite table in
/// sqrt(X) below X = 12 (5e-9 from the power series), the asymptotic series above.
std::complex<double> utdTransition(double x);

/// e^{-j kl} for a path's phase kl (radians, any size): reduced to [-pi, pi] in double
/// precision, then sine and cosine in single (within 2e-7 of the exact phasor: the edge paths'
/// band averages need nothing finer, and the single-precision pair is several times cheaper).
std::complex<double> pathPhasor(double kl);

/// The Fresnel integral int_0^u e^{-jt^2} dt for any real u (odd in u; tends to
/// (sqrt(pi) / 2) e^{-j pi / 4} as u grows): its power series for |u| <= 1, else the limit
/// minus utdTransition(u^2) e^{-ju^2} / (2ju). Within 1e-5 absolute.
std::complex<double> fresnelIntegral(double u);

/// Frequency-independent parts of one term cot((pi + sign x) / 2n) F(k L a_sign(x)) of the
/// coefficient: the cotangent and a_sign(x) = 2 cos^2((2 pi n N - x) / 2), N the integer
/// nearest (x + sign pi) / (2 pi n). On a shadow or reflection boundary (cot infinite, F zero)
/// the term is evaluated 1e-5 rad off it, where the product is finite and continuous.
struct UtdTerm {
  double cot = 0.0, a = 0.0;
};

/// The four terms for wedge index n (air wedge n pi) and angles phi (receiver), phiSource,
/// both in (0, n pi) from face 0: phi - phiSource with signs +, -, then phi + phiSource.
std::array<UtdTerm, 4> utdWedgeTerms(double n, double phi, double phiSource);

/// The magnitude of the coefficient's prefactor without its 1 / sqrt(k):
/// 1 / (2 n sqrt(2 pi) sin beta0), sin beta0 clamped to at least 1e-9.
double utdPrefactor(double n, double sinBeta0);

/// D sqrt(k) = -e^{-j pi/4} prefactor * sum over the terms of cot F(kl a), kl = k L.
std::complex<double> utdScaled(const std::array<UtdTerm, 4>& terms, double prefactor, double kl);

/// Orders of the transition function's asymptotic series (utdTransition's, above X = 12).
inline constexpr int kUtdSeriesOrders = 8;

/// A path's four terms summed order by order for the asymptotic series: where every term's
/// X = kl a is past the series' switch, sum_t cot_t F(kl a_t) = sum_m (2m-1)!! (j / 2kl)^m S_m
/// with S_m = sum_t cot_t a_t^-m: one series per frequency instead of four. Terms with cot 0
/// add nothing and are left out (of aMin too).
struct UtdTermSums {
  std::array<double, kUtdSeriesOrders> s{};  ///< S_m, m = 0..7 (units of a^-m)
  double aMin = 0.0;                         ///< the smallest a of the terms kept
};
UtdTermSums utdTermSums(const std::array<UtdTerm, 4>& terms);

/// utdScaled(terms, prefactor, kl), by the order sums where kl * sums.aMin is past the switch
/// (equal to the four series' sum to rounding), else term by term. sums = utdTermSums(terms).
std::complex<double> utdScaled(const std::array<UtdTerm, 4>& terms, const UtdTermSums& sums,
                               double prefactor, double kl);

/// The coefficient D itself (units sqrt(m)) for wedge index n at wavenumber k: phi, phiSource
/// as above, sinBeta0 the sine of the angle between the incident ray and the edge, L the
/// distance parameter (m).
Complex utdCoefficient(double n, double k, double phi, double phiSource, double sinBeta0, double L);

}  // namespace dpc
