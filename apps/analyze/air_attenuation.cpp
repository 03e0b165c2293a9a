// dpc-analyze --air-attenuation T RH: the air absorption dpc applies, per octave band.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "apps/analyze/options.h"
#include "apps/analyze/report.h"
#include "common/air_absorption.h"
#include "common/bands.h"

namespace dpc::analyze {

int printAirAttenuation(const Options& o) {
  const double t = o.air[0], rh = o.air[1];
  if (!(t >= -50.0 && t <= 60.0) || !(rh >= 0.0 && rh <= 100.0)) {
    std::cerr << "dpc-analyze: --air-attenuation: temperature must be in [-50, 60] C and "
                 "humidity in [0, 100] %\n";
    return 1;
  }
  const Bands m = airEnergyAttenuationPerMetre(t, rh);
  nlohmann::ordered_json out = {{"temperatureC", t},
                                {"humidityPercent", rh},
                                {"bandCentresHz", kBandCentreHz},
                                {"energyAttenuationPerMetre", nlohmann::ordered_json::array()}};
  for (int b = 0; b < kNumBands; ++b) out["energyAttenuationPerMetre"].push_back(m[b]);
  if (o.json) {
    std::cout << dumpJson(out) << "\n";
  } else {
    std::printf("air attenuation at %.1f C, %.1f %% RH (ISO 9613-1)\n", t, rh);
    for (int b = 0; b < kNumBands; ++b)
      std::printf("  %5.0f Hz  m = %.3e 1/m  (%.2f dB/km)\n", kBandCentreHz[size_t(b)],
                  double(m[b]), double(m[b]) * 10.0 / std::log(10.0) * 1000.0);
  }
  return 0;
}

}  // namespace dpc::analyze
