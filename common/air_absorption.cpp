#include "common/air_absorption.h"

#include <cmath>

namespace dpc {

double airAttenuationDbPerMetre(double f, double temperatureC, double humidityPercent,
                                double pressureKPa) {
  const double T = temperatureC + 273.15;  // K
  const double T0 = 293.15;                // reference temperature, K
  const double T01 = 273.16;               // triple-point isotherm, K
  const double pr = 101.325;               // reference pressure, kPa
  const double pa = pressureKPa;
  // Annex B: saturation vapour pressure ratio psat/pr = 10^C.
  const double C = -6.8346 * std::pow(T01 / T, 1.261) + 4.6151;
  const double h = humidityPercent * std::pow(10.0, C) / (pa / pr);  // molar conc. of H2O, %
  // Eq. (3), (4): relaxation frequencies of oxygen and nitrogen, Hz.
  const double frO = (pa / pr) * (24.0 + 4.04e4 * h * (0.02 + h) / (0.391 + h));
  const double frN = (pa / pr) * std::pow(T / T0, -0.5) *
                     (9.0 + 280.0 * h * std::exp(-4.170 * (std::pow(T / T0, -1.0 / 3.0) - 1.0)));
  // Eq. (5).
  const double f2 = f * f;
  return 8.686 * f2 *
         (1.84e-11 * (pr / pa) * std::sqrt(T / T0) +
          std::pow(T / T0, -2.5) * (0.01275 * std::exp(-2239.1 / T) / (frO + f2 / frO) +
                                    0.1068 * std::exp(-3352.0 / T) / (frN + f2 / frN)));
}

Bands airEnergyAttenuationPerMetre(double temperatureC, double humidityPercent,
                                   double pressureKPa) {
  Bands m;
  for (int b = 0; b < kNumBands; ++b) {
    const double alpha =
        airAttenuationDbPerMetre(bandCentreExactHz(b), temperatureC, humidityPercent, pressureKPa);
    m[b] = float(alpha * std::log(10.0) / 10.0);
  }
  return m;
}

double speedOfSoundAt(double temperatureC) {
  return 331.3 * std::sqrt(1.0 + temperatureC / 273.15);
}

}  // namespace dpc
