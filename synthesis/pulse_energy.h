// The energy a filtered Dirac sequence carries per time bin in expectation over its pulses'
// random signs, given where its pulses are: what one realisation's band signal scatters around
// (synthesis/dirac_sequence.h). For x = h * s, s a sequence of pulses +-1 at samples n_p,
// E[sum_{n in bin} x[n]^2] = sum_p sum_{n in bin} h[n - n_p]^2, since the cross terms of two
// pulses carry independent signs; for two filters h and g of the same sequence likewise
// E[sum x_h x_g] = sum_p sum_n h[n - n_p] g[n - n_p].
#pragma once

#include <cstddef>
#include <vector>

namespace dpc {

/// A zero-phase filter's taps kept for pulseEnergyPerBin: h[i] at time i - centre.
struct CentredTaps {
  std::vector<float> taps;
  size_t centre = 0;
};

/// Per bin of binSamples samples over [0, length): sum over the pulses n_p of `sequence` (its
/// non-zero samples, weighted by their square) of sum_{n in bin, 0 <= n < length}
/// h[n - n_p] g[n - n_p]. h and g: the same centre and number of taps. Any thread; allocates
/// the result and the taps' running sum; no errors (binSamples >= 1).
std::vector<double> pulseEnergyPerBin(const std::vector<float>& sequence, size_t length,
                                      size_t binSamples, const CentredTaps& h,
                                      const CentredTaps& g);

/// Times -before .. after - 1 (samples) of zero-phase filters.
struct TapSupport {
  size_t before = 0, after = 1;
};

/// The times outside which each of the zero-phase filters h and g (time 0 at index 0, circular
/// over their common size, time -t at size - t) holds at most `tail` of its energy at each
/// side. Any thread; no allocation; no errors.
TapSupport commonSupport(const std::vector<float>& h, const std::vector<float>& g, double tail);

/// h's taps over `support`, centred. Any thread; allocates; no errors.
CentredTaps centredTaps(const std::vector<float>& h, TapSupport support);

}  // namespace dpc
