// Sound through a narrow slit: the gap between a door leaf and its frame, under a door, between
// a panel and a wall. Below the cut-on of its first symmetric cross mode (k w < 2 pi) a slit
// of width w carries one plane wave through its depth d, driven at its mouth by the blocked
// pressure 2 p_i and loaded on both sides by the radiation impedance of its mouth. This is the
// transmission-line model of slits and holes of F. P. Mechel, "The acoustic sealing of holes
// and slits in walls", J. Sound Vib. 111(2), 1986, 297-336 (Vigran, Building Acoustics, 2008,
// eq. 9.4, gives it for holes), after M. C. Gomperts, "The sound insulation of circular holes
// and slits", Acustica 14, 1964, 1-16, and M. C. Gomperts & T. Kihlman, "The sound
// transmission loss of circular and slit-shaped apertures in walls", Acustica 18, 1967,
// 144-150. Per unit length of the slit, with X = k_t w (k_t the wavenumber across the slit):
//
//   mouth impedance   z_r(X) = Z_r / (omega rho) = (1 / X^2) int_0^X (X - t) H0^(2)(t) dt,
//                     the baffled strip with uniform velocity (P. M. Morse & K. U. Ingard,
//                     Theoretical Acoustics, 1968, ch. 7, for the 2-D Green's function
//                     (omega rho / 2) H0^(2)(k |x - x'|) averaged over the strip);
//                     X -> 0: 1/2 + (j / pi) (ln(2 / X) - gamma + 3/2); X -> inf: 1 / X
//   transfer          q = t(X) p_i / (omega rho),  q the mouth's volume velocity per length,
//                     t = 2 / (2 z_r cos(k_t d) + j (1 / X + z_r^2 X) sin(k_t d))
//   transmission      tau = |t|^2 Re z_r / X at normal incidence, relative to the slit's area
//                     (about 10 at 63 Hz for a 1 cm slit in a thin wall: a narrow slit passes
//                     more than the sound falling on its area; tau -> 1 as X grows).
//
// In three dimensions the slit is a line source along its length: each element radiates
// jw rho q dz e^{-jkR} / (2 pi R) into the half-space on its far side (the wall is its
// baffle), so a point source (free field e^{-jkr} / r) gives at the listener
//
//   p = (j / 2 pi) t(X) D_S D_L e^{-jk(r + s)} / (r s) int_a^b e^{-j alpha (z - z0)^2} dz,
//   alpha = (k / 2) sin^2 beta (1 / r + 1 / s),  k_t = k sin beta,
//
// r and s the legs to the stationary point z0 on the slit's centre line (the line integral in
// the paraxial approximation, exact for an infinitely long slit by stationary phase; the
// finite slit [a, b] by the Fresnel integral), beta the angle between the source leg and the
// slit, D = sinc(X sin theta / 2) the strip's directivity toward each leg (theta from the
// slit's axis; 1 for a narrow slit; by reciprocity the same on the source side). Where z0
// lies beyond the slit's end (a door's top gap seen from beside the doorway), the path length
// is expanded to second order at the nearer end instead, where the integrand is largest:
// r + s -> phase + curvature (z - vertex)^2 with the legs, angles and derivatives taken there
// (the expansion at z0 overstated the far slit's level by the legs' shortfall, up to 4 dB
// 1.5 m past the end).
//
// Units: metres, rad/m; pressures relative to a unit point source. Threads: any; no
// allocation; no errors (arguments outside their ranges are clamped as stated).
#pragma once

#include <array>
#include <complex>
#include <glm/vec3.hpp>
#include <numbers>
#include <span>

namespace dpc {

/// z_r(X) above for X = k_t w, X clamped to [1e-9, 16]: the power series of the integral
/// (exact to 1e-12 over that range; the slit model is used up to X = 4 pi).
std::complex<double> stripRadiationImpedance(double x);

/// t(X) above for X = k_t w and kd = k_t d (the slit's depth d, 0 for a slit in a sheet).
std::complex<double> slitTransfer(double x, double kd);

/// tau above: the normal-incidence transmission coefficient relative to the slit's area.
double slitTransmissionCoefficient(double x, double kd);

/// The slit model holds fully up to the first symmetric cross mode, X = 2 pi (w = one
/// wavelength), and gives way to the slit's two edges (UTD) by X = 4 pi; it holds for slits
/// at least kSlitFullAspect times as long as wide and gives way below kSlitMinAspect (a
/// doorway, 1 m by 2 m, is an aperture whose edges UTD handles).
inline constexpr double kSlitFullX = 2.0 * std::numbers::pi;
inline constexpr double kSlitEndX = 4.0 * std::numbers::pi;
inline constexpr double kSlitFullAspect = 8.0;
inline constexpr double kSlitMinAspect = 4.0;

/// The slit model's share s in [0, 1] of a slit path's pressure at X = k_t w for a slit
/// `aspect` = length / width (the rest, 1 - s, is its edges' UTD field): 1 inside both limits
/// above, 0 outside, a raised-cosine step in log X and in log aspect between them.
double slitWeight(double x, double aspect);

/// One slit path from a source through a slit to a listener (the formula above).
struct SlitPath {
  double r = 1.0, s = 1.0;           ///< legs source -> z0 and z0 -> listener, m
  double sinBeta = 1.0;              ///< sine of the angle between the source leg and the slit
  double zFrom = -1.0, zTo = 1.0;    ///< the slit's ends along it relative to z0, m
  double sinSource = 0.0;            ///< sin theta of the source leg from the slit's axis
  double sinListener = 0.0;          ///< sin theta of the listener leg
  double width = 0.01, depth = 0.0;  ///< m
  /// The path length's expansion r + s ~ phase + curvature (z - z0)^2 (m, 1/m), z0 the vertex
  /// the ends are measured from; curvature 0: at the stationary point, phase r + s and
  /// curvature sin^2 beta (1 / r + 1 / s) / 2.
  double phase = 0.0, curvature = 0.0;
  /// A turned channel's free legs round a door stop's corners (engine/channel_turn.h), at the
  /// source's end and the listener's: how much longer (m) each chain is than the straight line
  /// from the slit's mouth, delta >= 0 (0: none). The field takes a screen's shadow loss past
  /// its value on the shadow boundary, per end: 20 log10(x / tanh x) dB, x = sqrt(2 pi N),
  /// N = 2 delta / lambda (Kurze & Anderson 1971, whose 5 dB on the boundary is left out so
  /// that the level joins the unobstructed leg's without a step; about 18 N dB for small N,
  /// 10 log10(2 pi N) deep in the shadow).
  std::array<double, 2> shadowExcess{0.0, 0.0};
};

/// p above at wavenumber k (> 0), the path's phase e^{-jk(r + s)} included.
std::complex<double> slitPressure(const SlitPath& path, double k);

/// Slits in one baffle load each other. Each slit's mouth radiates into the same half-spaces,
/// so the pressure on slit i is the sum over all slits: 2 p_i = 2 sum_j Z_ij q_j (both sides,
/// q in units of p / (omega rho)), Z_ii = z_r(X_i) (the mouth impedance above) and, for two
/// parallel slits d apart in one plane, Z_ij = (1/2) H0^(2)(k_t d): the baffled line source's
/// field (omega rho / 2) H0^(2)(k r) averaged over two strips narrow against d (Morse & Ingard,
/// ch. 7, as for z_r). At low frequencies slits a tenth of a wavelength apart (a door's side
/// gaps, the gap between two leaves) share much of their radiation resistance, and each passes
/// less than alone: summed as independent, the four slits of a double door with 10 mm gaps
/// passed 0.9 dB more than the open doorway at 63 Hz, against Rayleigh's principle that an
/// orifice conducts less when made smaller (Theory of Sound, 1896, sec. 306). Slits that are
/// not parallel or not in one plane are not coupled (a door's top gap and its side gaps meet
/// only at the corners). For slits in a thin sheet (depth 0).
struct CoupledSlit {
  glm::dvec3 point{0.0};   ///< a point of its centre line, m
  glm::dvec3 along{0.0};   ///< unit direction along it
  glm::dvec3 normal{0.0};  ///< unit normal of its baffle's plane
  double x = 0.0;          ///< k_t w
  double kt = 0.0;         ///< k sin beta, rad/m
  std::complex<double> incident;  ///< incident pressure at its mouth (any common scale)
};

/// factors[i] = q_i (coupled: Z q = p) / (p_i / Z_ii) (alone), for i < slits.size() <=
/// factors.size(); 1 for a slit coupled to none, or when Z is singular (Eigen's partial-pivot
/// LU leaves the solution not finite).
/// Any thread; allocates O(n^2); no errors.
void mutualLoading(std::span<const CoupledSlit> slits, std::span<std::complex<double>> factors);

}  // namespace dpc
