// Per-band gain envelopes that give the band-filtered parts s_b = a_b * s of one Dirac sequence
// (synthesis/dirac_sequence.h, synthesis/band_filters.h) the band energies of an energy
// response: ir[n] = sum_b g_b[j(n)] s_b[n] with one gain per band and synthesis bin.
//
// Synthesis bins are 1 ms x 2^p wide, the smallest such width holding 2 periods of the band
// centre (32 ms at 63 Hz ... 1 ms from 2 kHz up); a band's bin is a whole number of the next
// band's bins, so neighbours' gains are constant or change only at bin boundaries.
//
// g_b[j] = sqrt(E_b[j] beta_b / e_b[j]): a response's band value E_b is a spectral density
// (synthesis/band_filters.h), so a band measurement with M_b sees E_b beta_b of it; e_b = beta_b
// x the pulses' energy in the bin (beta_b: the share of a unit impulse's energy that a band
// measurement with M_b sees), or realised energy where `measured` gives it (63 Hz; 125 Hz in
// the spatial synthesiser), and a crossover correction with the white-spectrum coupling
// coefficients. The gains are set in expectation and never
// corrected per realisation here (a gain target / realised, applied to a band signal of which a
// measurement sees only part, inflates the part it does not see on average); the mono
// synthesiser's band signals carry their expectation per window instead (TiltedBands,
// synthesis/band_tilt.h), and its octave views are levelled after (synthesis/window_leveller.h).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "common/bands.h"
#include "common/fftw_util.h"
#include "engine/energy_response.h"
#include "synthesis/band_filters.h"
#include "synthesis/late_rotation.h"

namespace dpc {

/// Gains g_b[j] per band and synthesis bin (see the file comment). The energy of a bin without
/// pulses goes to the nearer bin with pulses, the earlier one only from the band's first bin
/// with energy on (a sparse sequence's next pulse can lie tens of milliseconds on early in a
/// large room, or in an open scene's bounding volume). Construction allocates; compute() allocates only on its first call;
/// accumulate() does not. Propagation thread; no errors.
class BandEnvelope {
 public:
  /// Bands that may be normalised by realised rather than expected energy (63 and 125 Hz: a
  /// noise realisation there has too few degrees of freedom, e.g. 60 Hz x 0.3 s, to be near its
  /// expectation). A band whose `measured` signal is empty uses the expectation instead (the
  /// mono synthesiser levels the 125 Hz sequence per window: TiltedBands::kLevelledFromBand).
  static constexpr int kRealisedBands = 2;

  /// measured: for b < kRealisedBands, the sequence through M_b^3 (what a
  /// band measurement with M_b sees of the A_b-filtered sequence), length samples; e_b[j] is
  /// its energy in bin j. Other bands, and a band whose signal is empty, use the expected
  /// energy (beta_b x the pulses' energy).
  BandEnvelope(int sampleRate, const std::vector<float>& sequence, size_t length,
               const BandFilterData& filters,
               const std::array<std::vector<float>, kRealisedBands>& measured);
  /// Synthesis bin width of band b in samples at sampleRate (see the file comment).
  static size_t binSamplesFor(int sampleRate, int b);

  /// Reads the sequence circularly shifted from here on (synthesis/late_rotation.h): the
  /// gains of later compute() calls follow the shifted sequence's pulse energies, and
  /// accumulateRange() and startAt() read the band signals through the shift. `rotation`'s
  /// start, span and shift must be multiples of binSamplesFor(sampleRate, 0). The default
  /// LateRotation is no shift. No allocation.
  void rotate(const LateRotation& rotation);
  /// Gains for an energy response (any bin width; a negative bin counts as 0).
  void compute(const EnergyResponse& energy);
  /// out[n] += scale * sum_b g_b[j(n)] x_b[n] for the band signals x_b (length samples each).
  void accumulate(const std::array<const float*, kNumBands>& bands, float* out,
                  float scale = 1.f) const {
    accumulateRange(bands, out, 0, length_, scale);
  }
  /// The same for samples [begin, end) and bands [bandBegin, bandEnd) only (cache-blocked
  /// accumulation of many signals; band subsets).
  void accumulateRange(const std::array<const float*, kNumBands>& bands, float* out, size_t begin,
                       size_t end, float scale = 1.f, int bandBegin = 0,
                       int bandEnd = kNumBands) const;
  /// Makes the envelope causal at sample `onset` (the first arrival): the part of each band's
  /// synthesis bin that straddles it is to be rendered from `onset` on only (accumulateRange
  /// with begin = onset), so its gain is raised by sqrt(E_bin / E_from_onset), E the band
  /// signal's energy, and the bin keeps its energy. Bins before onset hold no energy (nothing
  /// arrives before the first arrival). No allocation.
  void startAt(size_t onset, const std::array<const float*, kNumBands>& bands);
  size_t binSamples(int b) const { return binSamples_[size_t(b)]; }
  /// Band b's gains g_b[j] of the last compute(), one per synthesis bin.
  const std::vector<float>& gains(int b) const { return gain_[size_t(b)]; }
  /// Energy of the last compute() that no gain could place (a bin whose neighbours' crossover
  /// spill alone exceeds its target, or energy after the sequence's last pulse), summed over
  /// bins, per band, in the response's unit.
  const std::array<double, kNumBands>& unplacedEnergy() const { return unplaced_; }

 private:
  void targets(const EnergyResponse& energy);
  void binTargets(const EnergyResponse& energy, int b);
  size_t moveToNearestPulses(int b);
  void carryToPulses(int b);
  void holdGainsOverEmptyBins(int b, size_t onset);
  /// Crossover correction of the gains (see the file comment).
  void correctCrossovers();
  int sampleRate_;
  size_t length_;
  BandCoupling coupling_;  ///< the band filters' (BandFilterData::coupling)
  /// beta_b (BandFilterData::share): a response's band value E_b is a spectral density (a
  /// white IR of energy E_b has E_b in every band), so a band measurement with M_b sees
  /// E_b beta_b of it.
  std::array<double, kNumBands> share_{};
  std::array<size_t, kNumBands> binSamples_{};
  std::array<std::vector<double>, kNumBands> baseEnergy_;      ///< e_b[j], unshifted
  std::array<std::vector<double>, kNumBands> sequenceEnergy_;  ///< e_b[j] as rotation_ reads it
  LateRotation rotation_;
  std::array<std::vector<double>, kNumBands> target_;          ///< scratch: E_b[j]
  std::array<std::vector<float>, kNumBands> gain_;             ///< g_b[j]
  std::array<std::vector<float>, kNumBands> wanted_;           ///< scratch: uncorrected g_b[j]
  std::array<double, kNumBands> unplaced_{};
};

/// The constructor's `measured` signals: the sequence (whose spectrum fft.spec holds) through
/// M_b^3 for the bands b < min(bands, kRealisedBands), length samples each, empty for the
/// others (fft.n >= length; masks of fft.n points). Allocates; a thread that may run fft's
/// plans; no errors.
std::array<std::vector<float>, BandEnvelope::kRealisedBands> measureLowBands(
    FftwRealTransforms& fft, const OctaveBandMasks& masks, size_t length,
    int bands = BandEnvelope::kRealisedBands);

}  // namespace dpc
