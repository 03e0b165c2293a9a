// Atmospheric absorption of sound per octave band (ISO 9613-1:1993).
//
// Control/propagation thread; allocation-free; no errors (inputs are validated by the scene
// loader: temperature in degrees C, relative humidity in percent, pressure in kPa).
#pragma once

#include "common/bands.h"

namespace dpc {

/// Pure-tone attenuation coefficient alpha in dB per metre at frequency fHz,
/// ISO 9613-1:1993 eq. (3)-(5) with the saturation vapour pressure of its Annex B.
double airAttenuationDbPerMetre(double fHz, double temperatureC, double humidityPercent,
                                double pressureKPa = 101.325);

/// Energy attenuation constant m per band in 1/metre, so that the energy left after a path
/// of length r metres is exp(-m * r). m = alpha * ln(10) / 10, alpha evaluated at the exact
/// base-2 band centre frequency (IEC 61260-1).
Bands airEnergyAttenuationPerMetre(double temperatureC, double humidityPercent,
                                   double pressureKPa = 101.325);

/// Speed of sound in dry air, m/s: 331.3 * sqrt(1 + T/273.15) (ideal-gas approximation).
double speedOfSoundAt(double temperatureC);

}  // namespace dpc
