// The within-band spectral tilt shared by the mono synthesiser (IrSynthesizer) and the
// analysis-side model of an exact IR (analysis/expected_band_analysis.h): a band's spectral
// density (band energy / octave width) taken log-linear in log frequency between octave-band
// centres, as air absorption and most materials change smoothly with frequency.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "common/fftw_util.h"
#include "engine/energy_response.h"
#include "synthesis/band_filters.h"
#include "synthesis/pulse_energy.h"

namespace dpc {

/// Mean spectral density of an octave's lower and upper halves relative to the density at its
/// centre (see halfBandDensity).
struct HalfBandDensity {
  double low, high;
};
/// Width of the response window the tilt is read from, seconds.
inline constexpr double kTiltWindowSeconds = 0.02;
inline constexpr double kTiltMaxLog = 10.0;  ///< a density ratio of e^10 (43 dB)

/// From the response's energies of the octaves below, at and above `band` over
/// kTiltWindowSeconds centred on centreSeconds: mean over x in [0, 1/2] of
/// (D_{band-1} / D_band)^x and (D_{band+1} / D_band)^x (log ratio clamped to +-kTiltMaxLog).
/// 1 for a missing neighbour (63 Hz below, 8 kHz above) or an octave without energy there.
/// Any thread; no allocation; no errors.
HalfBandDensity halfBandDensity(const EnergyResponse& energy, int band, double centreSeconds);

/// halfBandDensity for many windows of one response in O(1) each: per band the suffix sums of
/// the response's (non-negative) band energies, so a window's energy is a difference of two
/// (a decaying response's later tail is of the window's order, so the difference keeps about
/// full double precision; a window of zeros reads exactly 0). Consecutive queries of a band
/// whose window covers the same response bins return the previous result.
/// reset(): propagation thread; allocates only while a response has more bins than any before.
/// at(): same thread; no allocation; no errors.
class TiltWindowSums {
 public:
  void reset(const EnergyResponse& energy);
  HalfBandDensity at(int band, double centreSeconds);

 private:
  double binSeconds_ = 1.0;
  size_t bins_ = 0;
  /// suffix_[k][b]: the sum over i >= k of max(0, e_i[b]), k in [0, bins_].
  std::vector<std::array<double, kNumBands>> suffix_;
  struct Last {
    size_t k0 = 0, k1 = 0;
    HalfBandDensity value{1.0, 1.0};
    bool valid = false;
  };
  std::array<Last, kNumBands> last_{};
};

/// The mono synthesiser's band signals and their within-band tilt per synthesis bin
/// (BandEnvelope::binSamplesFor). Per band: s_b = a_b * s (the Dirac sequence through A_b) and
/// its upper half s_hi (through A_b P, P = powerAbove(f, fc), so s_b = s_lo + s_hi with
/// s_lo = A_b (1 - P)); per bin the weights alpha (s_b) and gamma (s_hi) and the tilted signal
/// alpha s_b + gamma s_hi, whose upper half carries mean_{x in [0, 1/2]} (D_{b+1} / D_b)^x and
/// lower half likewise toward D_{b-1} (halfBandDensity), scaled to keep the band's expected
/// energy within its analysed octave (inAnalysedOctave). Without it, a band decaying much slower
/// than the band above (4 kHz under 8 kHz in a large hall: air absorption) keeps its slow decay up
/// to its upper edge, where the octave above's analysis filter passes it.
/// From kLevelledFromBand up, each band's realisation is levelled to its expectation: s_b and
/// s_hi are made from the sequence with its pulses scaled per window (kLevellingPeriods), the
/// factors iterated (kSequenceLevelling times) so that each window's energy of s_b equals what
/// it carries in expectation over the pulses' random signs given their places
/// (synthesis/pulse_energy.h).
/// The envelope's gains are set for that expectation, so one realisation's band energy per bin
/// is the response's rather than scattered around it; the factor is the energy of the very
/// signal it scales over that signal's sign-averaged energy (nothing a filter does not see is
/// inflated), and it scales the pulses before the band filter, so the band signal stays within
/// its band (scaling s_b per bin instead makes steps that splatter: the 63 Hz band's spread in
/// ir_synthesis_test grew from 0.55 to 0.64 dB rms).
/// Construction: a thread that may run fft's plans (fft.spec holds the spectrum of `sequence`,
/// kept, fft.n >= length; masks of fft.n points); allocates 3 x kNumBands x length floats and
/// runs 2 kSequenceLevelling + 1 transforms per levelled band; no errors. With
/// Levelling::kDeferred it leaves the levelling to level() (the band signals are then the
/// unlevelled s_b and s_hi, a realisation whose band energies scatter around their
/// expectation): what a first IR needs, in a quarter of the transforms. update(): propagation
/// thread; no allocation; no errors.
class TiltedBands {
 public:
  /// Bands whose realisation is levelled (125 Hz up: 63 Hz is normalised by realised energy in
  /// BandEnvelope, kRealisedBands); the iterations; the window, whole synthesis bins of at
  /// least this many periods of the band centre (80 ms at 125 Hz, 40 at 250 Hz, 20 at 500 Hz,
  /// 10 at 1 kHz, 5 at 2 kHz, 3 at 4 kHz); and the largest factor either way one iteration
  /// applies to a window's pulses. 125 Hz's gains set from each 16 ms bin's realised energy
  /// instead put its part after 80 ms +0.6 dB above the response on average (its level and C80
  /// 0.3-0.5 dB off in BRAS CR2: a ratio target / realised over a few degrees of freedom,
  /// applied as gain steps the band filter smears across bins;
  /// tests/synthesis/low_band_windows_test.cpp). Per bin (2 periods), where A_b's response is
  /// longer than a bin, the iteration neither converged (0.5-0.8 dB rms per bin left after 3)
  /// nor kept the total (+0.12 dB). Shorter windows level more of a realisation's scatter, but
  /// a filter that sees part of s_b (the octave below's analysis filter its lower skirt) reads
  /// that part times E[expected / realised] > 1 (fewer degrees of freedom, more): with 250 Hz
  /// levelled and 125 Hz following realised energy, ir_synthesis_test's 125 Hz band read
  /// +0.33 dB with 6 periods and +0.29 with 10.
  static constexpr int kLevelledFromBand = 1;
  static constexpr int kSequenceLevelling = 3;
  static constexpr double kLevellingPeriods = 10.0;
  static constexpr double kMaxSequenceFactor = 4.0;
  /// When the bands' realisations are levelled: at construction, or by level().
  enum class Levelling { kAtConstruction, kDeferred };
  /// shareScratch: TiltedBands of the same length whose tilted() buffers this one writes too
  /// (they hold one update()'s result, read before the next update() of either: synthesisers
  /// that run one at a time on one thread); nullptr: its own.
  TiltedBands(int sampleRate, size_t length, const std::vector<float>& sequence,
              const OctaveBandMasks& masks, FftwRealTransforms& fft,
              const TiltedBands* shareScratch = nullptr,
              Levelling levelling = Levelling::kAtConstruction);
  /// Levels the bands as construction with kAtConstruction does (the same bits): `sequence`
  /// the one given to the constructor, fft scratch of the constructor's size. Nothing when they
  /// are levelled. Allocates; the same thread rules as update(), and not during an update() of
  /// this object; no errors.
  void level(const std::vector<float>& sequence, FftwRealTransforms& fft);
  bool levelled() const { return levelled_; }
  /// Sets every bin's weights and tilted signal from the response (any bin width).
  void update(const EnergyResponse& energy);

  /// s_b and s_hi, length samples.
  const std::vector<float>& band(int b) const { return band_[size_t(b)]; }
  const std::vector<float>& upperHalf(int b) const { return upper_[size_t(b)]; }
  /// alpha s_b + gamma s_hi per bin of the last update(), length samples.
  const std::vector<float>& tilted(int b) const { return (*tilted_)[size_t(b)]; }
  /// The tilted() buffers: a workspace TiltedBands of one length may share (shareScratch).
  using Scratch = std::shared_ptr<std::array<std::vector<float>, kNumBands>>;
  const Scratch& scratch() const { return tilted_; }
  /// Writes tilted() into s from now on: s from a TiltedBands of this length, not written by
  /// another update() before this one's tilted() are read. No allocation.
  void useScratch(const Scratch& s) { tilted_ = s; }
  /// alpha and gamma of bin j of the last update().
  float alpha(int b, size_t j) const { return alpha_[size_t(b)][j]; }
  float gamma(int b, size_t j) const { return gamma_[size_t(b)][j]; }

 private:
  int sampleRate_;
  size_t length_;
  std::array<std::vector<float>, kNumBands> band_, upper_;
  std::shared_ptr<std::array<std::vector<float>, kNumBands>> tilted_;
  /// <s_lo,s_lo>, <s_lo,s_hi>, <s_hi,s_hi> for a white input.
  std::array<std::array<double, 3>, kNumBands> halfEnergy_{};
  std::array<std::vector<float>, kNumBands> alpha_, gamma_;
  /// What every TiltedBands of one FFT size computes alike, made once and shared
  /// (shareScratch): per band the filter gains on the FFT bins, A_b and A_b P (the upper
  /// half's share, powerAbove), 1/n included; the half-bands' white-noise energies; and the
  /// levelled bands' taps of A_b (pulseEnergyPerBin).
  struct Filters {
    size_t n = 0;
    std::array<std::vector<float>, kNumBands> band, upper;
    std::array<std::array<double, 3>, kNumBands> half{};
    std::array<CentredTaps, kNumBands> taps;
  };
  /// The filters for fft.n points (fft.band and fft.time: scratch; fft.spec kept).
  static std::shared_ptr<const Filters> makeFilters(int sampleRate, const OctaveBandMasks& masks,
                                                    FftwRealTransforms& fft);
  /// out <- the first length_ samples of fft.spec through the bins' gains (fft.band, fft.time:
  /// scratch).
  void filterInto(const std::vector<float>& gain, FftwRealTransforms& fft,
                  std::vector<float>& out) const;
  /// Scales band b's pulses per window so that s_b's energy in each is its expectation, and
  /// remakes s_b and s_hi from them (fft.spec: scratch).
  void levelSequence(int b, const std::vector<float>& sequence, FftwRealTransforms& fft);
  std::shared_ptr<const Filters> filters_;
  bool levelled_ = false;
  TiltWindowSums windows_;  ///< update()'s scratch
};

}  // namespace dpc
