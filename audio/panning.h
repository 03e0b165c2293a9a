// Stereo amplitude panning of an arrival direction: constant-power (sine/cosine) pan law.
//
// Listener frame as in audio/hrtf.h (SOFA listener coordinates): x forward, y left, z up;
// `dir` points from the listener towards where the sound comes from. The azimuth
// phi = atan2(y, x) is folded onto the frontal half-plane (a two-loudspeaker stereo pair
// cannot tell front from back): phi_f = atan2(y, |x|) in [-90, 90] degrees; elevation is
// ignored (only the direction's horizontal projection counts). The pan position
// p = (phi_f + 90 deg) / 180 deg in [0, 1] (0 = hard right, 1 = hard left) gives
//   gL = sin(p * pi/2),   gR = cos(p * pi/2),   so gL^2 + gR^2 = 1 for every direction,
// the constant-power ("sine/cosine", -3 dB at centre) pan law: a centred source has
// gL = gR = 1/sqrt(2), i.e. -3.01 dB per channel, and the total radiated power is the same
// wherever it is panned. References: A. D. Blumlein, British patent 394,325 (1931);
// V. Pulkki, "Virtual sound source positioning using vector base amplitude panning", JAES 45(6),
// 456-466 (1997), which states the constant-power normalisation gL^2 + gR^2 = 1. This maps
// the whole frontal half-plane onto the loudspeaker pair (hard left at +90 degrees), rather
// than the tangent law over a +-30 degree loudspeaker base: a deliberate simplification so
// that every arrival direction lands between the speakers.
//
// A direction straight up or down, or a zero / non-finite vector, has no horizontal component
// and is treated as centre. Pure function; any thread, including the audio thread: no
// allocation, no locks, no exceptions.
#pragma once

namespace dpc::audio {

/// Constant-power stereo gains for `dir` (listener frame, need not be unit length). Writes
/// linear amplitude gains in [0, 1] with (*left)^2 + (*right)^2 = 1 (to float rounding).
void stereoGains(const float dir[3], float* left, float* right);

}  // namespace dpc::audio
