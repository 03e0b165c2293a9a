// The synthesis band filters: the octave-band masks M_b and amplitude-complementary filters
// A_b = M_b^2 of common/octave_band_masks.h (sum_b A_b = 1, so equal band gains give back the
// unfiltered signal and neighbouring bands never add up coherently to more than it), their
// crossover coupling for a white spectrum, and the impulse responses a_b of A_b that place a
// direct sound (shared by the mono and the spatial synthesiser).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <numbers>
#include <span>
#include <utility>
#include <vector>

#include "common/bands.h"
#include "common/fftw_util.h"
#include "common/octave_band_masks.h"

namespace dpc {

/// Taps of the zero-phase band filters a_b and the FFT padding that leaves room for their
/// tails: 1/4 s at sampleRate Hz. Any thread; no allocation; no errors.
inline size_t bandFilterTaps(int sampleRate) {
  return size_t(sampleRate / 4);
}

/// The same for the filters a_b of bands firstBand up alone: each crossover is a raised cosine
/// over a fixed fraction of an octave (powerAbove), so its impulse response scales in time with
/// 1 / its frequency, and bandFilterTaps, set by the lowest crossover (63 / 125 Hz), shrinks by
/// that crossover's frequency over the lowest one kept, with the same relative tail left out:
/// bandFilterTaps / 2^(firstBand - 1) for firstBand >= 1 (750 taps at 48 kHz from 2 kHz up).
/// Any thread; no allocation; no errors.
inline size_t bandFilterTapsFrom(int sampleRate, int firstBand) {
  return firstBand <= 1 ? bandFilterTaps(sampleRate)
                        : std::max<size_t>(2, bandFilterTaps(sampleRate) >> (firstBand - 1));
}

/// Crossover coupling of the band masks for a white spectrum:
/// coupling[b][i][k] = sum_f M_b^2 A_{b+i-1} A_{b+k-1} / sum_f M_b^2, the share of band b's
/// measured energy that the product of the gains of bands b+i-1 and b+k-1 contributes.
using BandCoupling = std::array<std::array<std::array<double, 3>, 3>, kNumBands>;

/// The band filters' fixed data for one sample rate: coupling and each band's energy share
/// beta_b (the fraction of a unit impulse's energy that a band measurement with M_b sees).
/// compute(): any thread; no allocation; no errors.
struct BandFilterData {
  BandCoupling coupling{};
  std::array<double, kNumBands> share{};
  static BandFilterData compute(const OctaveBandMasks& masks, size_t fftSize);
};

/// One deterministic arrival that the direct-sound filters place (the direct sound or an exact
/// early path): its delay in seconds and band intensities (1/m^2 relative to source power).
struct Arrival {
  double delaySeconds = 0.0;
  Bands intensity{0.f};
};

/// Merges the arrivals that land on the same sample at sampleRate Hz into one, their band
/// amplitudes sqrt(intensity) added (pressures at one instant add coherently: three equal image
/// sources on one sample carry 9, not 3, times one's energy), and sorts them by delay. Any
/// thread; no allocation; no errors.
void mergeCoincidentArrivals(std::vector<Arrival>& arrivals, int sampleRate);

/// Energy, relative to everything up to 1 ms after the first arrival, that
/// cutLeadingResidue may remove ahead of it: -80 dB.
inline constexpr double kLeadingResidueEnergy = 1e-8;

/// Sets to exactly zero the leading samples of an IR (`channels`, each `length` samples) whose
/// energy summed over the channels is at most kLeadingResidueEnergy of the energy summed over
/// the channels up to 1 ms after `onset` (the first arrival's sample); one cut for all
/// channels, so their relative timing is kept. What lies there is the zero-phase band
/// filters' ringing ahead of the first arrival (their pulses' leading taps and the band
/// levelling's circular split), no arrival: the cut removes at most -80 dB of the IR's sound up
/// to the first arrival (a channel far weaker than the others, the far ear or a high-order
/// Ambisonic channel, may lose up to that ratio more of its own) and lets a partitioned
/// convolver skip the partitions ahead of it. Returns the samples zeroed. Any thread; no
/// allocation; no errors.
size_t cutLeadingResidue(std::span<float* const> channels, size_t length, size_t onset,
                         int sampleRate);

/// The direct-sound filters: per band the impulse response a_b of A_b (zero phase), `taps`
/// samples long with time 0 at index centre() = taps / 2. Its energy as a band measurement with
/// M_b sees it is beta_b (BandFilterData::share) per unit amplitude. Construction: a thread that
/// may run the FFTW plans of `fft` (masks of fft.n points; taps <= fft.n); allocates
/// kNumBands x taps floats; no errors. The accessors and add(): any thread; no allocation.
class DirectSoundFilter {
 public:
  DirectSoundFilter(const OctaveBandMasks& masks, FftwRealTransforms& fft, size_t taps);
  /// a_b, centred at centre().
  const std::vector<float>& band(int b) const { return filter_[size_t(b)]; }
  size_t centre() const { return centre_; }
  size_t taps() const { return filter_[0].size(); }
  /// Taps of a_b that add() touches (its support).
  size_t support(int b) const {
    return support_[size_t(b)].second - support_[size_t(b)].first;
  }
  /// out[start + i] += amplitude x a_b[i] for the i with start + i in [0, length), over a_b's
  /// support (the taps outside it carry less than kNegligibleTailEnergy of its energy).
  void add(int b, float amplitude, long start, float* out, size_t length) const;
  /// Energy fraction of a_b's leading and trailing taps that add() skips, each side: -100 dB,
  /// below float's rounding of the band's own peak (the higher bands' filters are short, the
  /// 63 Hz one spans most of its taps).
  static constexpr double kNegligibleTailEnergy = 1e-10;

 private:
  /// [begin, end) of the taps of h outside which each side's energy is negligible.
  static std::pair<size_t, size_t> supportOf(const std::vector<float>& h);
  std::array<std::vector<float>, kNumBands> filter_;
  std::array<std::pair<size_t, size_t>, kNumBands> support_{};
  size_t centre_;
};

}  // namespace dpc
