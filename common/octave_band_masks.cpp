#include "common/octave_band_masks.h"

#include <algorithm>
#include <cmath>

namespace dpc {

namespace {
/// 2^(-1/6) and 2^(1/6): the crossover's edges relative to its centre.
constexpr double kCrossoverBelow = 0.89089871814033930;
constexpr double kCrossoverAbove = 1.12246204830937302;
}  // namespace

double powerAbove(double f, double edge) {
  constexpr double halfWidth = 1.0 / 6.0;  // octaves either side of the edge
  // Outside the crossover without a logarithm (called for every bin of long FFTs).
  if (f <= edge * kCrossoverBelow) return 0.0;
  if (f >= edge * kCrossoverAbove) return 1.0;
  const double x = std::log2(f / edge);
  if (x >= halfWidth) return 1.0;
  if (x <= -halfWidth) return 0.0;
  const double s = std::sin(0.25 * std::numbers::pi * (1.0 + x / halfWidth));
  return s * s;
}

OctaveBandMasks::OctaveBandMasks(int sampleRate, size_t fftSize) {
  const size_t bins = fftSize / 2 + 1;
  for (auto& g : gains_) g.assign(bins, 0.f);
  for (size_t k = 0; k < bins; ++k) {
    const double f = double(k) * sampleRate / double(fftSize);
    // Power fraction passed above each edge e_b (between band b and b+1): powerAbove.
    double prevUpper = 1.0;  // fraction of power above the edge below band 0 (there is none)
    for (int b = 0; b < kNumBands; ++b) {
      const double upper =
          b < kNumBands - 1 ? powerAbove(f, bandCentreExactHz(b) * std::numbers::sqrt2) : 0.0;
      const double power = prevUpper - upper;  // in band b: above edge b-1, below edge b
      gains_[size_t(b)][k] = float(std::sqrt(std::max(0.0, power)));
      prevUpper = upper;
    }
  }
}

}  // namespace dpc
