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

/// The mono synthesiser's band signals and their within-band tilt per synthesis bin
/// (BandEnvelope::binSamplesFor). Per band: s_b = a_b * s (the Dirac sequence through A_b) and
/// its upper half s_hi (through A_b P, P = powerAbove(f, fc), so s_b = s_lo + s_hi with
/// s_lo = A_b (1 - P)); per bin the weights alpha (s_b) and gamma (s_hi) and the tilted signal
/// alpha s_b + gamma s_hi, whose upper half carries mean_{x in [0, 1/2]} (D_{b+1} / D_b)^x and
/// lower half likewise toward D_{b-1} (halfBandDensity), scaled to keep the band's expected
/// energy within its analysed octave (inAnalysedOctave). Without it, a band decaying much slower
/// than the band above (4 kHz under 8 kHz in a large hall: air absorption) keeps its slow decay up
/// to its upper edge, where the octave above's analysis filter passes it. Per bin it also gives the
/// tilted signal's realised energy and the energy it carries in expectation over the sequence's
/// random signs given its pulses (synthesis/pulse_energy.h), for levelling one realisation to its
/// expectation (BandEnvelope::levelRealisation). Construction: a thread that may run fft's plans
/// (fft.spec holds the spectrum of `sequence`, fft.n >= length; masks of fft.n points); allocates 3
/// x kNumBands x length floats; no errors. update(): propagation thread; no allocation; no errors.
class TiltedBands {
 public:
  /// shareScratch: TiltedBands of the same length whose tilted() buffers this one writes too
  /// (they hold one update()'s result, read before the next update() of either: synthesisers
  /// that run one at a time on one thread); nullptr: its own.
  TiltedBands(int sampleRate, size_t length, const std::vector<float>& sequence,
              const OctaveBandMasks& masks, FftwRealTransforms& fft,
              const TiltedBands* shareScratch = nullptr);
  /// Sets every bin's weights and tilted signal from the response (any bin width).
  void update(const EnergyResponse& energy);

  /// s_b and s_hi, length samples.
  const std::vector<float>& band(int b) const { return band_[size_t(b)]; }
  const std::vector<float>& upperHalf(int b) const { return upper_[size_t(b)]; }
  /// alpha s_b + gamma s_hi per bin of the last update(), length samples.
  const std::vector<float>& tilted(int b) const { return (*tilted_)[size_t(b)]; }
  /// alpha and gamma of bin j of the last update().
  float alpha(int b, size_t j) const { return alpha_[size_t(b)][j]; }
  float gamma(int b, size_t j) const { return gamma_[size_t(b)][j]; }
  /// Per band and bin of the last update(): the tilted signal's energy, and its expectation
  /// over the pulses' signs.
  const std::array<std::vector<double>, kNumBands>& realisedEnergy() const { return realised_; }
  const std::array<std::vector<double>, kNumBands>& expectedEnergy() const { return expected_; }

 private:
  int sampleRate_;
  size_t length_;
  std::array<std::vector<float>, kNumBands> band_, upper_;
  std::shared_ptr<std::array<std::vector<float>, kNumBands>> tilted_;
  /// <s_lo,s_lo>, <s_lo,s_hi>, <s_hi,s_hi> for a white input.
  std::array<std::array<double, 3>, kNumBands> halfEnergy_{};
  std::array<std::vector<float>, kNumBands> alpha_, gamma_;
  /// Per band and bin, the sign-averaged energies of s_b s_b, s_b s_hi and s_hi s_hi.
  std::array<std::array<std::vector<double>, 3>, kNumBands> pulseEnergy_;
  std::array<std::vector<double>, kNumBands> realised_, expected_;
  /// pulseEnergy_[b] from the sequence and band b's filters A_b and A_b P (fft.band: scratch).
  void pulseEnergies(int b, const std::vector<float>& sequence, const OctaveBandMasks& masks,
                     FftwRealTransforms& fft);
};

}  // namespace dpc
