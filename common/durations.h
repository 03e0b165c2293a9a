// How many whole samples cover a length in seconds (an impulse response's). The energy
// response's 1 ms bins keep their own count (engine/energy_response.cpp): a bake's shape and
// settings hash are made of it, and bakes already written must still load.
//
// Lengths reach the engine as single-precision floats (a scene's ir_length, the C API's
// options): 0.1 s is stored as 0.100000001 s, and ceil(0.100000001 * 48000) is 4801 samples,
// one more than the user asked for. A length within single-precision rounding of a whole
// number of steps counts as that number. Any thread; no allocation.
#pragma once

#include <cmath>
#include <cstddef>

namespace dpc {

/// Relative tolerance of a length given in single precision: 2^-20, 16 times float's epsilon
/// (2^-24 relative rounding), so a float length rounded up still counts its whole steps.
inline constexpr double kSinglePrecisionLengthTolerance = 0x1p-20;

/// ceil(seconds / stepSeconds), with a length within kSinglePrecisionLengthTolerance of a
/// whole number of steps counted as that number. seconds >= 0, stepSeconds > 0.
inline size_t stepsCovering(double seconds, double stepSeconds) {
  const double steps = seconds / stepSeconds;
  return size_t(std::ceil(steps * (1.0 - kSinglePrecisionLengthTolerance)));
}

}  // namespace dpc
