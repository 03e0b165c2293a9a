// Room acoustic parameters (ISO 3382-1) from an impulse response or an energy decay.
//
// Reverberation times come from Schroeder's backward integration of the squared pressure
// (M. R. Schroeder, "New method of measuring reverberation time", JASA 37, 409-412, 1965;
// ISO 3382-1:2009 clause 5.3.3, "integrated impulse response method"): the decay curve
// L(t) = 10 log10( ∫_t^∞ p² / ∫_onset^∞ p² ) dB, then a least-squares line L = a + b t over a
// level range, and the time for a 60 dB decay, -60 / b (ISO 3382-1:2009 clause 5.3 and
// Annex A):
//   T20: range -5 .. -25 dB (i.e. 3 x the 20 dB decay time),
//   T30: range -5 .. -35 dB (2 x the 30 dB decay time),
//   EDT: range  0 .. -10 dB (6 x the 10 dB decay time).
// Energy ratios relative to the direct-sound arrival ("onset", time t0), ISO 3382-1:2009
// Annex A:
//   C50 = 10 log10( E[t0, t0+50 ms) / E[t0+50 ms, ∞) ) dB,  C80 likewise with 80 ms,
//   D50 = E[t0, t0+50 ms) / E[t0, ∞)  (a ratio 0..1, not %).
//
// Background noise (impulse responses only; analysis/noise_floor.h). Each band's and the
// broadband squared IR is searched for a stationary noise floor by the iterative method of
// Lundeby et al. (Acustica 81, 344-355, 1995). Where one is found, ISO 3382-1:2009 clause 5.3.3's
// compensation applies: the backward integration starts at the crossing of the late decay and
// the noise, the fitted decay's exponential tail beyond it is added, and all parameters
// (including C, D and the energy) come from that curve. The noise before the crossing stays in
// (no subtraction), which lengthens the decay a little: an exponential decay (T = 1 s) over a
// floor 50 dB down reads T30 +1.2 %, 41.6 dB down T20 +1.6 % (the method's value for the expected
// energy; measured means agree within 0.4 %). A tail that falls at the decay's rate or lies on
// its extrapolation is no floor (a record cut while the decay still runs, as dpc's own are): it
// is analysed by the 90 % rule below. An energy decay (analyzeEnergyDecay) is dpc's own,
// noise-free, and is not searched.
//
// Honest NaN. A reverberation time is NaN (never an invented number) when
//   * the decay curve never falls to the lower end of its range, or
//   * the lower end is not at least 10 dB above the curve's "end floor": with a noise floor
//     found, the curve's level at the crossing (about the noise's level below the decay's
//     start, so T30 needs the noise >= 45 dB down, T20 35 dB, EDT 20 dB); without, its level
//     at 90 % of the record after the onset. A finite record always makes the
//     backward-integrated curve plunge at its end (truncation); ISO 3382-1 asks for the
//     evaluation range to end at least 10 dB above the noise, which is what this rule
//     enforces. Consequence: T30 needs a record whose curve reaches about -45 dB before 90 % of
//     its length (an exponential decay recorded for >= ~0.85 T60), T20 about -35 dB, EDT about
//     -20 dB;
//   * fewer than kMinRegressionPoints samples/bins lie within the range.
// A noise floor found less than 20 dB below the decay's peak gives every parameter NaN but the
// energy. C50/C80 are +inf when no energy arrives after 50/80 ms (an ideal single impulse),
// -inf when none arrives before; C and D are NaN when the IR holds no energy at all, and when
// the record ends (or meets its noise floor) less than 50/80 ms after the onset (its late part
// was never recorded). A floor the method does not recognise (one reached only within the last
// 10 % of the record, a decay less than about 20 dB above it, a low band's tail too scattered
// to tell: analysis/noise_floor.h) is not compensated: the 90 % rule above applies.
//
// Threads: any thread except the audio thread (allocates scratch buffers); the functions are
// pure and re-entrant. Errors: none thrown for finite input; n == 0 gives all-NaN results.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "common/bands.h"

namespace dpc::audio {

/// One set of ISO 3382-1 parameters. Times in seconds, C in dB, D50 a ratio in [0, 1].
struct RoomParameters {
  double t20, t30, edt;  ///< s
  double c50, c80;       ///< dB
  double d50;            ///< ratio 0..1
  /// Energy from the onset on: sum of squared samples (IR) or of the bins (energy decay), in
  /// the input's unit; dpc's IRs and energy responses are in 1/m^2 relative to source power,
  /// so 10 log10(energy / (1 / (4 pi 10^2))) is the strength G (ISO 3382-1 A.2.1: relative to
  /// the free-field direct sound at 10 m). An IR's octave band b is divided by
  /// analysisFilterImpulseEnergy(b): the free-field reference measured through the same filter,
  /// so a band reads the energy response's band value (a spectral density, see
  /// synthesis/band_filters.h). NaN when the input holds no energy.
  double energy = std::numeric_limits<double>::quiet_NaN();
  /// Impulse-response-to-noise ratio: the decay's highest 20 ms-scale interval above the
  /// stationary noise floor found (analysis/noise_floor.h, Lundeby 1995), dB. NaN when no
  /// floor was found (and always for energy decays, which are not searched).
  double inrDb = std::numeric_limits<double>::quiet_NaN();
  /// Where the backward integration stops because the decay meets that floor (ISO 3382-1:2009
  /// 5.3.3), s from the onset; NaN when no floor was found.
  double truncationSeconds = std::numeric_limits<double>::quiet_NaN();
};

/// Strength G in dB from RoomParameters::energy on dpc's scale (relative to 1/(4 pi 10^2)).
inline double strengthDb(double energy) {
  return 10.0 * std::log10(energy * 4.0 * 3.14159265358979323846 * 100.0);
}

/// Energy of a unit impulse through octave band b's analysis filter (below) at sampleRate Hz,
/// rung out: about the band's share of a white spectrum (0.0018 at 63 Hz, 0.24 at 8 kHz, at
/// 48 kHz). NaN where the band cannot be filtered (upper edge at or above Nyquist). Any
/// thread; no allocation.
double analysisFilterImpulseEnergy(int b, double sampleRate);

/// Parameters per octave band (63 Hz .. 8 kHz, index as dpc::Bands) and broadband.
struct ImpulseResponseAnalysis {
  std::array<RoomParameters, kNumBands> bands;
  RoomParameters broadband;  ///< from the unfiltered IR
};

/// Minimum number of decay-curve points a regression must use, else the time is NaN.
inline constexpr size_t kMinRegressionPoints = 3;

/// Analyses a pressure impulse response `ir` of `n` samples at `sampleRate` Hz.
///
/// Onset (direct-sound arrival, t0): the first sample whose squared value is within 20 dB of
/// the squared peak of the broadband IR (ISO 3382-1:2009 A.3.4: the start lies where the signal
/// rises above the noise but not more than 20 dB below the peak). The same broadband t0 is
/// used for every band, so the octave filters' group delay (a few ms at 63 Hz) counts as late.
///
/// Octave bands: IEC 61260-1 octave filters, each a 6th-order Butterworth band-pass (3rd-order
/// low-pass prototype) realised as three biquads from the bilinear transform with both band
/// edges prewarped, so the digital response is exactly the analog Butterworth one at prewarped
/// frequencies: -3.01 dB at the edges fc·2^(±1/2) around the exact base-2 centre
/// fc = 1000·2^(b-4), about -19.6 dB one octave away, unity gain at the centre (within 1e-6 dB
/// at fc). Run forward in time, double precision. A band whose upper edge is at or above
/// Nyquist (the 8 kHz band, edge 11.3 kHz, at fs <= 22.6 kHz) cannot be filtered as specified
/// and gets all-NaN parameters rather than an aliased or truncated band.
/// Filter delay and ringing bias short decays in low bands (measured at 63 Hz with T60 =
/// 0.5 s, B·T60 = 22: T30 +5 %, EDT +20..40 %); keep B·T60 above ~30 for EDT (ISO 3382-1 asks
/// B·T > 16 for T20/T30).
///
/// Noise floors: found and compensated per band and broadband as the file comment says.
///
/// Allocates O(n) doubles. Not for the audio thread.
ImpulseResponseAnalysis analyzeImpulseResponse(const float* ir, size_t n, int sampleRate);

/// Energy per octave band of an impulse response in time bins from its onset: what the band
/// analysis of analyzeImpulseResponse integrates, binned (backward sums give each band's
/// Schroeder decay curve, e.g. to plot against an energy response's).
struct BandEnergyBins {
  double onsetSeconds;  ///< broadband onset t0 (same rule as analyzeImpulseResponse), s from
                        ///< the IR's first sample; NaN when the IR holds no energy
  double binSeconds;    ///< bin width used: the request rounded to whole samples (>= 1), s
  /// energy[b][k]: sum of the squared band-b signal over [t0 + k binSeconds, t0 + (k+1)
  /// binSeconds) (the last bin may be partial), divided by analysisFilterImpulseEnergy(b) (as
  /// RoomParameters::energy: on the energy response's scale). Empty for a band whose upper edge reaches Nyquist, and for
  /// every band when the IR holds no energy.
  std::array<std::vector<double>, kNumBands> energy;
};

/// The band energies of `ir` (n samples at sampleRate Hz) through the IEC 61260-1 filters of
/// analyzeImpulseResponse, in bins of binSeconds (> 0) from the onset. Invalid arguments give
/// NaN times and empty bands. Allocates O(n). Not for the audio thread.
BandEnergyBins bandEnergyBins(const float* ir, size_t n, int sampleRate, double binSeconds);

/// Parameters of one energy envelope already per band, e.g. one band of an energy response
/// histogram: energy[k] is the energy (any unit) in time bin k = [k·binSeconds,
/// (k+1)·binSeconds). Bin 0 starts at emission. The onset t0 is onsetSeconds (s from emission:
/// the direct sound's arrival, where an IR's analysis above finds it) when that lies inside the
/// first non-zero bin, whose energy then counts from t0 to the bin's end; otherwise (NaN, the
/// default) the start of that bin. With the bin's start instead of the direct sound's arrival,
/// the 80 ms split lands up to a bin early, and C80 reads up to 0.1 dB below an IR's in a 1 s
/// room with 1 ms bins. The Schroeder curve is sampled at t0 and the later bins' starts,
/// L(k) = 10 log10(Σ_{j>=k} energy[j] / Σ_{j>=onset} energy[j]); C50/C80/D50 split the bin that
/// straddles t0 + 50/80 ms in proportion to time (cumulative energy interpolated linearly).
/// Same NaN rules as above. Negative energies are treated as zero. Allocates O(n). Not for the
/// audio thread.
RoomParameters analyzeEnergyDecay(const double* energy, size_t n, double binSeconds,
                                  double onsetSeconds = std::numeric_limits<double>::quiet_NaN());

}  // namespace dpc::audio
