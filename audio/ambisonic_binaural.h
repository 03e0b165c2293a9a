// Binaural decoding of an AmbiX (ACN, SN3D) signal through an HRTF: (N + 1)^2 x 2 filters
// (channel c, ear) and a diffuse-field equaliser common to both ears. Two decoders:
//
// MagLS (the default): least squares of the complex HRTF below 1.5 kHz, magnitude least
// squares above, fitted to the SOFA set's measured directions (Schörkhuber, Zaunschirm,
// Höldrich, DAGA 2018), optionally with the diffuse-field covariance constraint (Zaunschirm et
// al., JASA 2018): audio/magls_decoder.h. Above the cut-off it keeps the HRTF's magnitudes,
// hence the interaural level differences, that an order-N spatially band-limited HRTF loses.
//
// Sampling: the virtual-loudspeaker decoder (Noisternig, Musil, Sontacchi, Höldrich, "3D
// binaural sound reproduction using a virtual ambisonic approach", VECIMS 2003; the sampling
// decoder of Zotter & Frank, "Ambisonics", 2019, ch. 4). Q virtual loudspeakers u_q on a
// Gauss-Legendre (N + 2 rings) x equiangular (2N + 4) quadrature with weights w_q (exact
// beyond degree 2N) get the feeds
//   s_q = w_q / (4 pi) sum_n (2n + 1) sum_m Y_n^m(u_q) b_nm,
// so a plane wave from s feeds them the band-limited delta sum_n (2n+1) P_n(u_q . s) w_q / 4 pi
// (summing to 1). Each feed goes through the HRIR pair of its direction (onset delays as
// leading zeros); folded per channel, channel c has one filter per ear,
//   F_c,ear = sum_q w_q / (4 pi) (2n + 1) Y_c(u_q) h_ear(u_q).
// Plain (basic) weights, no high-frequency treatment: above about N c / (2 pi r) (1.9 kHz at
// order 3 for a head radius of 8.75 cm) its ILD is that of a spatially band-limited HRTF,
// lower than the HRTF's (docs/spatial.md, "Binaural decoding"). Kept for that comparison.
//
// Diffuse-field equalisation (both decoders): both ears' decoded signals pass through one
// minimum-phase filter E = sum_b A_b / sqrt(D_b), A_b the amplitude-complementary octave-band
// filters of common/octave_band_masks.h and D_b the band power the decoder gives the ears (mean
// of both; A_b-weighted over band b's analysed octave) for an isotropic diffuse field of unit
// power, in which an SN3D channel of order n carries power 1 / (2n + 1):
// D(f) = sum_c |F_c,ear(f)|^2 / (2 n_c + 1). Below kDirectionalFromBand (63 and 125 Hz, which
// per-path binaural renders without HRIRs) 1 / sqrt(D_b) is replaced by 1 / sqrt(D(f)) smoothed
// over third octaves, flattening the HRTF's steep roll-off within those bands. The ears then
// hear a diffuse field at its own power in every octave band, levelled in the same bands and
// with the same crossovers as per-path binaural levels its HRIRs by the HRTF set's
// diffuse-field band power (synthesis/spatial_synthesizer.h), instead of the HRTF's low-frequency
// roll-off (and, for the sampling decoder, its high-frequency loss: the virtual loudspeakers' HRIRs
// add incoherently there, keeping about (N + 1)^2 / Q of the power). Within a band E is flat, as
// per-path binaural's levelling is, so that a band's interaural level difference weighs the ears'
// spectra alike in both renderers (a finer, third-octave equaliser tilted the 4 kHz band and moved
// its ILD at 90 degrees by about 1 dB against per-path binaural: docs/spatial.md). Common to both
// ears, E leaves interaural time differences unchanged. Minimum phase by folding the real cepstrum
// (Oppenheim & Schafer, "Discrete-Time Signal Processing", 3rd ed., sec. 13.6); boost limited to
// kMaxEqualiserBoostDb.
//
// Construction: control thread, allocates (ambisonicChannels(order) x 2 filters and the
// equaliser; plans FFTW). decode(): any thread except the audio thread (direct convolution,
// O(n (L C + E)); allocates two scratch signals of n samples).
#pragma once

#include <array>
#include <vector>

#include "audio/hrtf.h"
#include "audio/magls_decoder.h"

namespace dpc::audio {

/// Which decoder (see the file comment).
enum class BinauralDecoderMethod { kMagLs, kSampling };

struct BinauralDecoderOptions {
  BinauralDecoderMethod method = BinauralDecoderMethod::kMagLs;
  MagLsOptions magLs;  ///< MagLS only
};

class AmbisonicBinauralDecoder {
 public:
  /// order 1 .. kMaxAmbisonicOrder (clamped). Throws std::invalid_argument when MagLS is
  /// asked of a set with fewer measurements than channels.
  AmbisonicBinauralDecoder(int order, const Hrtf& hrtf, const BinauralDecoderOptions& options = {});

  /// Largest boost of the diffuse-field equaliser, dB (the HRTF's power far below its
  /// measured band is not restored beyond this).
  static constexpr double kMaxEqualiserBoostDb = 24.0;
  /// Taps of the diffuse-field equaliser (85 ms at 48 kHz: octave bands from 250 Hz, a
  /// third-octave-smooth response below, down to about 40 Hz).
  static constexpr size_t kEqualiserTaps = 4096;

  BinauralDecoderMethod method() const { return method_; }
  /// Taps of every channel's ear filter: the HRIR length plus 2 ms (the sampling decoder's
  /// onset delays; MagLS's spread around the set's bulk delay).
  size_t filterLength() const { return length_; }
  /// Channel c's filter for ear 0 (left) or 1 (right).
  const std::vector<float>& filter(size_t c, int ear) const { return filters_[c][size_t(ear)]; }
  /// The diffuse-field equaliser both ears go through after the channel filters
  /// (kEqualiserTaps taps, minimum phase).
  const std::vector<float>& equaliser() const { return equaliser_; }
  /// Adds to left/right (n samples each) the decoded, equalised ears of the
  /// ambisonicChannels(order) planar channels (n samples each), truncated to n samples.
  void decode(const float* const* channels, size_t n, float* left, float* right) const;

 private:
  /// Computes equaliser_ from the folded filters (the HRTF's sampleRate, Hz, places the bands).
  void equaliseDiffuseField(int sampleRate);

  int order_;
  BinauralDecoderMethod method_;
  size_t length_ = 0;
  ChannelEarFilters filters_;
  std::vector<float> equaliser_;
};

}  // namespace dpc::audio
