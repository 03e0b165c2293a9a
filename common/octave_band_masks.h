// Zero-phase, power-complementary octave-band masks M_b on the bins of a real FFT (raised-cosine
// crossovers 1/3 octave wide at the band edges fc * 2^(1/2)): sum_b M_b^2 = 1 on every bin, so
// A_b = M_b^2 are amplitude-complementary band filters (sum_b A_b = 1). One definition shared by
// the IR synthesis (synthesis/band_filters.h: band split, direct sound, per-band diffuse-field
// levelling) and the Ambisonic binaural decoder's diffuse-field equaliser
// (audio/ambisonic_binaural.h), so that both renderers level a diffuse field in the same bands.
#pragma once

#include <array>
#include <cstddef>
#include <numbers>
#include <vector>

#include "common/bands.h"

namespace dpc {

/// The lowest octave band (index into kBandCentreHz: 250 Hz) that spatial renderings carry per
/// direction; the bands below it (63 and 125 Hz) are rendered omnidirectionally: too few
/// wavelengths fit a head or a room's reflections for directions to be heard there, and too few
/// independent noises fit the band to keep its energy (synthesis/spatial_synthesizer.h).
inline constexpr int kDirectionalFromBand = 2;

/// Whether band b has an ISO 3382-1 analysis filter at sampleRate Hz (common/octave_filter.h:
/// its upper edge fc sqrt(2) lies below Nyquist; 8 kHz at 22.05 kHz does not). Any thread; no
/// allocation; no errors.
inline bool analysableBand(int b, double sampleRate) {
  return bandCentreExactHz(b) * std::numbers::sqrt2 < 0.5 * sampleRate;
}

/// Whether an octave-band analysis counts band b's mask at f Hz: everywhere for the inner
/// bands, from fc / sqrt 2 up for the 63 Hz band and up to fc sqrt 2 for the 8 kHz band (their
/// masks reach on to 0 Hz and to Nyquist). Any thread; no allocation; no errors.
inline bool inAnalysedOctave(int b, double f) {
  const double fc = bandCentreExactHz(b);
  if (b == 0) return f >= fc / std::numbers::sqrt2;
  if (b == kNumBands - 1) return f <= fc * std::numbers::sqrt2;
  return true;
}

/// Fraction of power above `edge` Hz at f Hz: a raised cosine in log2 frequency over +-1/6
/// octave around the edge (a 1/3-octave crossover); with its complement (1 - it) it splits
/// power without loss (sin^2 + cos^2 = 1). Any thread; no allocation; no errors.
double powerAbove(double f, double edge);

/// Zero-phase power-complementary octave-band masks M_b on the bins 0..fftSize/2 of a real FFT
/// of fftSize points at sampleRate Hz (sum_b M_b^2 = 1 on every bin). Any thread; the
/// constructor allocates kNumBands x (fftSize/2 + 1) floats; no errors.
class OctaveBandMasks {
 public:
  OctaveBandMasks(int sampleRate, size_t fftSize);
  /// |H_b| at FFT bin k (0 <= k <= fftSize/2).
  float gain(int band, size_t k) const { return gains_[size_t(band)][k]; }
  size_t binCount() const { return gains_[0].size(); }

 private:
  std::array<std::vector<float>, kNumBands> gains_;
};

}  // namespace dpc
