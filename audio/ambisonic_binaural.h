// Binaural decoding of an AmbiX (ACN, SN3D) signal through an HRTF: the virtual-loudspeaker
// sampling decoder (Noisternig, Musil, Sontacchi, Höldrich, "3D binaural sound reproduction
// using a virtual ambisonic approach", VECIMS 2003; the sampling decoder of Zotter & Frank,
// "Ambisonics", 2019, ch. 4).
//
// Q virtual loudspeakers u_q on a Gauss-Legendre (N + 2 rings) x equiangular (2N + 4)
// quadrature with weights w_q (exact beyond degree 2N) get the feeds
//   s_q = w_q / (4 pi) sum_n (2n + 1) sum_m Y_n^m(u_q) b_nm,
// so a plane wave from s feeds them the band-limited delta sum_n (2n+1) P_n(u_q . s) w_q / 4 pi
// (summing to 1). Each feed goes through the HRIR pair of its direction (onset delays as
// leading zeros); folded per channel, channel c has one filter per ear,
//   F_c,ear = sum_q w_q / (4 pi) (2n + 1) Y_c(u_q) h_ear(u_q).
// Plain (basic) weights: no max-rE, no MagLS high-frequency treatment, so above about
// N c / (2 pi r) (1.9 kHz at order 3 for a head radius of 8.75 cm) the ILD is that of a
// spatially band-limited HRTF.
//
// Construction: control thread, allocates (ambisonicChannels(order) x 2 filters). decode():
// any thread except the audio thread (direct convolution, allocates nothing, O(n L C)).
#pragma once

#include <array>
#include <vector>

#include "audio/hrtf.h"

namespace dpc::audio {

class AmbisonicBinauralDecoder {
 public:
  AmbisonicBinauralDecoder(int order, const Hrtf& hrtf);

  /// Taps of every channel's ear filter (HRIR length plus the largest onset delay).
  size_t filterLength() const { return length_; }
  /// Channel c's filter for ear 0 (left) or 1 (right).
  const std::vector<float>& filter(size_t c, int ear) const { return filters_[c][size_t(ear)]; }
  /// Adds to left/right (n samples each) the decoded ears of the ambisonicChannels(order)
  /// planar channels (n samples each), truncated to n samples.
  void decode(const float* const* channels, size_t n, float* left, float* right) const;

 private:
  int order_;
  size_t length_ = 0;
  std::vector<std::array<std::vector<float>, 2>> filters_;
};

}  // namespace dpc::audio
