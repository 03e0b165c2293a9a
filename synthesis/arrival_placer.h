// Places the deterministic arrivals of an IR (the direct sound and the exact early paths) as
// band-shaped pulses sum_b sqrt(I_b) a_b at their samples, a_b the zero-phase band filters of
// synthesis/band_filters.h. Adding a_b tap by tap costs its support per arrival, and the low
// bands' supports are long (the 63-500 Hz filters span their whole 1/4 s: the crossovers are
// 1/3 octave wide), while their masks are zero above a few hundred bins. So the bands below a
// split are summed on those bins (each arrival a phase ramp, a twiddle per bin) and brought to
// time by one inverse FFT per IR; the bands above it, whose filters are short, are added tap by
// tap. The split is the band that minimises the per-arrival work (bins against taps). The result
// equals the tap-by-tap sum within the filters' truncation (DirectSoundFilter::
// kNegligibleTailEnergy, -100 dB) and float rounding.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "common/fftw_util.h"
#include "common/octave_band_masks.h"
#include "synthesis/band_filters.h"

namespace dpc {

class ArrivalPlacer {
 public:
  /// masks: the masks of fftSize points that `direct`'s filters were made from;
  /// fftSize >= length + direct->taps() for every IR length placed, so that no pulse's ringing
  /// wraps into the IR. Construction: a thread that may plan FFTW (takes fftwPlannerMutex);
  /// allocates about fftSize floats; throws std::bad_alloc, std::runtime_error when FFTW
  /// cannot plan, std::invalid_argument when fftSize is not the masks' size.
  ArrivalPlacer(const OctaveBandMasks& masks, std::shared_ptr<const DirectSoundFilter> direct,
                size_t fftSize);
  ~ArrivalPlacer();
  ArrivalPlacer(const ArrivalPlacer&) = delete;
  ArrivalPlacer& operator=(const ArrivalPlacer&) = delete;

  /// ir[n] += sum over arrivals and bands of sqrt(intensity_b) a_b[n - n_a] for n in
  /// [0, length), n_a the sample nearest the arrival's delay at the filters' sample rate
  /// (sampleRate Hz). Arrivals whose pulse lies wholly outside [0, length) add nothing.
  /// One thread at a time per placer (it owns its workspace); no allocation; no errors.
  void place(std::span<const Arrival> arrivals, int sampleRate, float* ir, size_t length);

  /// Bands [0, split()) are placed on FFT bins, the rest tap by tap.
  int split() const { return split_; }
  /// FFT bins [0, bins()) that the bands below the split occupy.
  size_t bins() const { return bins_; }

 private:
  /// The split and its bins: the band F minimising bins(F) x kBinCost + the supports of the
  /// bands from F up (per arrival).
  void chooseSplit(const OctaveBandMasks& masks);
  /// Adds one arrival at sample n0 to the spectrum, bands below the split: gain_ per bin, then
  /// the phase ramp e^{-2 pi i k n0 / n} by recurrences (sixteen bins a step), seeded exactly
  /// from the tables every kSeedBins bins: at most 32 float rotations, whose rounding stays
  /// near 1e-6 of the phase.
  void addToSpectrum(const Arrival& a, long n0);
  /// The spectrum brought to time and added to ir[0, length); the sums cleared.
  void addSpectrumToIr(float* ir, size_t length);

  /// Twiddle e^{-2 pi i m / n} for any m (reduced mod n): a coarse and a fine table's product.
  void twiddle(size_t m, float& re, float& im) const;

  /// Work of one bin (a quarter of four-wide complex multiply-adds and a rotation) in taps' work.
  static constexpr double kBinCost = 2.0;
  /// The fine table's size: m = hi x kFine + lo.
  static constexpr size_t kFine = 256;
  static constexpr size_t kSeedBins = 512;

  std::shared_ptr<const DirectSoundFilter> direct_;
  size_t n_;
  int split_ = 0;
  size_t bins_ = 0;
  /// Bins [bandStart_[b], bandStart_[b + 1]) have band b as the lower of their (at most two)
  /// bands below the split; lowGain_ and highGain_ hold A_b and A_{b+1} there (0 at the split).
  std::vector<size_t> bandStart_;
  std::vector<float> lowGain_, highGain_;
  std::vector<float> gain_, accRe_, accIm_;  ///< per bin (padded to 4): one arrival's, the sum
  std::vector<float> coarse_, fine_;  ///< cos, sin of -2 pi m / n_ interleaved (m = hi kFine, lo)
  FftwArray<fftwf_complex> spec_;     ///< n_/2 + 1 bins; the inverse FFT runs in place
  fftwf_plan inverse_ = nullptr;
};

}  // namespace dpc
