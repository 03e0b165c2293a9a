// The stationary background-noise floor of a squared impulse response, by the iterative method
// of A. Lundeby, T. E. Vigran, H. Bietz, M. Vorländer, "Uncertainties of measurements in room
// acoustics", Acustica 81, 344-355 (1995), for the noise compensation of ISO 3382-1:2009
// clause 5.3.3 (the backward integration starts where the decay meets the noise, and the energy
// the decay would carry beyond that point is added as a correction).
//
// The iteration, on the energy e[k] (squared pressure, one value per sample of dt seconds):
//   1. the mean of e in intervals of 20 ms, in dB;
//   2. the noise: the mean of e over the last 10 % of the record;
//   3. a line fitted (least squares, dB against time) from the envelope's peak down to 10 dB
//      above the noise;  4. its crossing with the noise level;
//   5. intervals re-chosen: 5 per 10 dB of that line's decay;
//   7. the noise: the mean of e from 10 dB of decay past the crossing (at least the last 10 %);
//   8. the late decay: a line through the envelope from 30 dB to 10 dB above the noise;
//   9. its crossing with the noise; 7-9 repeated (at most 5 times) until the crossing moves by
//      less than one interval.
// Lundeby's step numbers; his ranges are 10-50 ms (1), 3-10 intervals per 10 dB (5), 5-10 dB
// (3, 7, 8) and a 10-20 dB late range (8); the values above are choices within them. A range
// runs from its first interval below the upper level to its last one above the lower level
// before the noise region, the intervals between included: a band's envelope fades (Rayleigh)
// would otherwise end it at the first dip.
//
// A floor is reported (found) only when the tail really is one: over the noise region (step 7)
//   * the mean energy lies at least 6 dB, and 3 standard errors of the late line's level there,
//     above the late line's extrapolation, and
//   * the envelope's own slope is less than a quarter of the late line's (or of a line through
//     the whole decay, peak to 10 dB above the noise), by 3 standard errors of the slopes, and
//   * that slope is the one a stationary floor under the late line would give there (the
//     least-squares slope of 10 lg(floor + line)), within 3 standard errors or 5 % of the late
//     line's slope.
// A floor 5 dB past the crossing falls at most a quarter as fast as the decay (the decay adds
// at most 10^-0.5 of the noise). A record merely cut while its decay still runs (dpc's own
// responses) fails: its tail falls at the decay's rate and lies on its extrapolation. A second,
// slower decay (coupled rooms, a ringing mode) fails the last test: it keeps falling. Such
// records, a record whose tail is exactly zero, a tail too short or too scattered to tell (a
// low band's few intervals), and one the iteration cannot fit (fewer than 3 intervals in a
// range, no decay, a crossing outside the record or inside its last 10 %) give found = false.
// Measured on 432 noise-free records (T60 0.3-2 s, cut at 0.3-2 T60, two-slope up to T2 = 2 T1,
// zero-padded): none found in 3888 band and broadband analyses; two-slope decays (T1 0.5 s,
// T2 2.5-8 T1, knee 25-35 dB down, 1-1.5 s): none in 32, where the first two tests alone took
// 10 for floors; 3 s records with a floor 35-60 dB down: found in 1132 of 1152 (the misses at
// 63 and 125 Hz). Step 6 (the interval length re-chosen) comes with step 5's choice.
//
// Units: e in any energy unit per sample, dt in seconds; NoiseFloor::noise and tailEnergy in
// e's unit (tailEnergy a sum over samples, as e is summed by the backward integration).
// Threads: any except the audio thread (allocates O(n / interval)); pure and re-entrant.
// Errors: none thrown; invalid input (dt <= 0, fewer than 20 samples) gives found = false.
#pragma once

#include <cstddef>
#include <limits>
#include <vector>

namespace dpc::audio {

/// What findNoiseFloor recognised. Fields other than `found` are meaningful only when found.
struct NoiseFloor {
  bool found = false;
  /// First sample not integrated: the decay meets the noise at crossing·dt s, 0 < crossing < n.
  size_t crossing = 0;
  double noise = std::numeric_limits<double>::quiet_NaN();  ///< mean energy per sample
  /// Correction for the energy lost by stopping at the crossing: the late line's exponential
  /// decay summed over the samples from `crossing` on (e's unit).
  double tailEnergy = 0.0;
  double decayDbPerSecond = std::numeric_limits<double>::quiet_NaN();  ///< late line's slope
  /// Noise region's mean over the late line's extrapolation there, dB (>= 6 when found; NaN
  /// when the iteration stopped before the verdict).
  double excessDb = std::numeric_limits<double>::quiet_NaN();
  /// The envelope's highest interval (final interval length) above the noise, dB.
  double peakAboveNoiseDb = std::numeric_limits<double>::quiet_NaN();
};

/// Lundeby's iteration (above) on the energy sequence e (e[0] at the onset), dt s per sample.
NoiseFloor findNoiseFloor(const std::vector<double>& e, double dt);

}  // namespace dpc::audio
