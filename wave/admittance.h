// Wall admittance of the wave band from a material's absorption coefficients.
//
// The grid's walls are locally reacting with a real normalised admittance beta = rho c / Z
// (frequency independent). A material's octave absorption coefficients are random-incidence
// (statistical) values, so beta is the one whose Paris statistical absorption
//   alpha_st(beta) = integral_0^{pi/2} alpha(theta) sin(2 theta) d theta,
//   alpha(theta) = 4 zeta cos(theta) / (zeta cos(theta) + 1)^2,  zeta = 1 / beta,
// equals the material's absorption coefficient in one octave band (wave/wave_band.h runs one
// simulation per octave band up to the crossover, each with its band's admittance, and splits
// the results at the band edges). Limits: within a band the wall is frequency independent,
// and
// alpha_st of a real admittance peaks at 0.951 (zeta = 1.567): more absorbing materials get
// that peak.
//
// Any thread; no allocation; no errors (alpha is clamped to [0, 0.951]).
// Source: H. Kuttruff, Room Acoustics (6th ed., 2017), section 2.5 (Paris' formula).
#pragma once

namespace dpc::wave {

/// The statistical absorption coefficient of a locally reacting wall of real normalised
/// admittance beta >= 0.
double statisticalAbsorption(double beta);

/// The real normalised admittance in [0, 1 / 1.567] whose statistical absorption is `alpha`.
double admittanceForAbsorption(double alpha);

}  // namespace dpc::wave
