// Sound transmission through a surface: a material's transmission loss R (dB per octave band,
// as measured in ISO 10140-2 and used in EN ISO 12354-1) and the energy transmission
// coefficient tau = 10^(-R/10) it implies. A material without "transmission_loss_db" is opaque
// (R = +infinity, tau = 0).
//
// Energy convention (docs/estimators.md, "Transmission"): the absorption coefficient alpha is
// Sabine's and counts the transmitted part as absorbed for the source room, so at a surface
// reflected = 1 - alpha, transmitted = tau, dissipated = alpha - tau >= 0; tau > alpha in a band
// is invalid input (scene/validate.cpp).
//
// Pure functions: any thread, no allocation, no errors.
#pragma once

#include <cmath>
#include <limits>

#include "common/bands.h"

namespace dpc {

/// R of an opaque material, dB.
inline constexpr float kOpaqueTransmissionLossDb = std::numeric_limits<float>::infinity();

/// tau = 10^(-R/10) per band (R in dB, >= 0; +infinity gives exactly 0).
inline Bands transmittanceOf(const Bands& transmissionLossDb) {
  Bands tau;
  for (int b = 0; b < kNumBands; ++b)
    tau[b] = std::isinf(transmissionLossDb[b]) ? 0.f
                                               : std::pow(10.f, -transmissionLossDb[b] / 10.f);
  return tau;
}

/// True when some band transmits (tau > 0).
inline bool transmits(const Bands& transmissionLossDb) {
  for (int b = 0; b < kNumBands; ++b)
    if (!std::isinf(transmissionLossDb[b])) return true;
  return false;
}

}  // namespace dpc
