// Source directivity: first-order patterns, per octave band.
//
// A first-order source radiates the energy gain g(theta) = ((1 - a) + a cos theta)^2 at the
// angle theta from its forward axis, a in [0, 1] its first-order coefficient: a = 0 is omni,
// 0.5 cardioid, 1 figure of eight (Eargle, "The Microphone Book", 2nd ed., Focal Press 2004,
// ch. 5, "First-order directional microphones": the polar equation rho = A + B cos theta,
// A + B = 1, and the same family's directivity factors; a source and a microphone of one
// pattern share it by reciprocity).
//
// Normalisation: dpc's sources have a given total radiated power (docs/design.md, "Energy
// convention"), so the weight applied to a direction is g(theta) / <g>, <g> the mean of g over
// the sphere, (1 - a)^2 + a^2 / 3. The total power is unchanged and the on-axis intensity rises
// by the directivity factor Q = 1 / <g> (cardioid: 3, +4.8 dB; hypercardioid: 4, +6.0 dB).
//
// Plain data and pure functions: any thread, no allocation, no errors.
#pragma once

#include <array>
#include <optional>
#include <string_view>

#include "common/bands.h"

namespace dpc {

/// A source's directivity: the first-order coefficient a per octave band, each in [0, 1]
/// (the limit "sources[].directivity.a"). All zero: omni, and the engine then applies no
/// weight at all (no float operation differs from an engine without directivity).
struct Directivity {
  Bands a{0.f};
  bool omni() const { return a == Bands(0.f); }
};

/// A named first-order pattern and its coefficient a.
struct DirectivityPattern {
  std::string_view name;
  float a;
};

/// The named patterns of the scene format's "directivity" (Eargle, op. cit., ch. 5).
inline constexpr std::array<DirectivityPattern, 6> kDirectivityPatterns = {{
    {"omni", 0.f},
    {"subcardioid", 0.3f},
    {"cardioid", 0.5f},
    {"supercardioid", 0.63f},
    {"hypercardioid", 0.75f},
    {"figure8", 1.f},
}};

/// The coefficient of a named pattern, or nullopt for a name not in kDirectivityPatterns.
inline std::optional<float> directivityPatternA(std::string_view name) {
  for (const DirectivityPattern& p : kDirectivityPatterns)
    if (p.name == name) return p.a;
  return std::nullopt;
}

/// Energy gain g = ((1 - a) + a cos theta)^2 relative to on-axis (dimensionless, [0, 1]).
inline float directivityGain(float a, float cosTheta) {
  const float p = (1.f - a) + a * cosTheta;
  return p * p;
}

/// Mean of directivityGain over the sphere, (1 - a)^2 + a^2 / 3; the directivity factor Q is
/// its inverse. At least 1/4 (a = 3/4) for a in [0, 1].
inline float directivityMeanGain(float a) {
  return (1.f - a) * (1.f - a) + a * a / 3.f;
}

/// Per band, the power-preserving weight g(theta) / <g> of a direction at cosTheta from the
/// forward axis (its mean over the sphere is 1).
inline Bands directivityWeight(const Directivity& d, float cosTheta) {
  Bands w;
  for (int b = 0; b < kNumBands; ++b)
    w[b] = directivityGain(d.a[b], cosTheta) / directivityMeanGain(d.a[b]);
  return w;
}

}  // namespace dpc
