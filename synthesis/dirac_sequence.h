// The carrier of the band-filtered Dirac sequence method (D. Schröder, "Physically Based
// Real-Time Auralization of Interactive Virtual Environments", PhD thesis, RWTH Aachen 2011,
// section 5.3): Poisson arrivals with random signs at the reflection density of a room
// (H. Kuttruff, "Room Acoustics", 5th ed., eq. 4.6: dN/dt = 4 pi c^3 t^2 / V), held within
// [kMinPulseDensity, a cap].
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace dpc {

/// Lowest Dirac-sequence density, pulses per second. The law 4 pi c^3 t^2 / V alone leaves an
/// open scene (V its bounding box, 10^8 m^3 for a 2 km square) without a pulse for the first
/// second, so every early reflection's energy would wait for a pulse up to a second later and
/// be heard as an echo; at 100 pulses/s the next pulse is 10 ms away on average, well inside
/// the echo threshold (about 50 ms). The floor changes the law only before
/// t = sqrt(100 V / (4 pi c^3)): 6 ms in 200 m^3, 54 ms in 15,000 m^3. Bins without energy
/// leave their pulses silent, so a denser carrier adds no sound of its own.
inline constexpr double kMinPulseDensity = 100.0;

/// Dirac sequence density cap of the synthesisers, pulses per second (Schröder 2011 uses about
/// this order).
inline constexpr double kMaxPulseDensity = 10000.0;

/// A Dirac sequence (Poisson arrivals of rate 4 pi c^3 t^2 / V per second held within
/// [kMinPulseDensity, maxDensity], random signs +-1), `length` samples at sampleRate Hz;
/// roomVolume m^3, speedOfSound m/s; the same seed gives the same sequence. Any thread;
/// allocates `length` floats; no errors (the caller checks the arguments).
std::vector<float> diracSequence(int sampleRate, size_t length, double roomVolume,
                                 double speedOfSound, double maxDensity, uint64_t seed);

}  // namespace dpc
