#include "synthesis/filter_shape.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include "synthesis/spatial_synthesizer.h"

namespace dpc {

size_t longestFilter(const std::vector<DirectionFilter>& filters, size_t channels, size_t margin) {
  if (channels == 0) throw std::invalid_argument("SpatialIrSynthesizer: filters need a channel");
  size_t longest = 1;
  for (const DirectionFilter& f : filters) {
    if (f.channels.size() != channels)
      throw std::invalid_argument("SpatialIrSynthesizer: every direction needs the same channels");
    for (const std::vector<float>& h : f.channels) {
      if (h.empty() || h.size() >= margin)
        throw std::invalid_argument("SpatialIrSynthesizer: filters must have 1 .. rate/4 taps");
      longest = std::max(longest, h.size());
    }
  }
  return longest;
}

size_t fieldDelay(const std::vector<DirectionFilter>& filters) {
  double sum = 0.0;
  size_t count = 0;
  for (const DirectionFilter& f : filters)
    for (const std::vector<float>& h : f.channels) {
      double e = 0.0, moment = 0.0;
      for (size_t t = 0; t < h.size(); ++t) {
        e += double(h[t]) * h[t];
        moment += double(t) * h[t] * h[t];
      }
      if (e <= 0.0) continue;
      sum += moment / e;
      ++count;
    }
  return count ? size_t(std::lround(sum / double(count))) : 0;
}

void delayFrom(size_t onset, size_t delay, size_t length, std::span<float* const> channels) {
  if (delay == 0 || onset >= length) return;
  const size_t kept = length - onset > delay ? length - onset - delay : 0;
  for (float* out : channels) {
    if (kept > 0) std::copy_backward(out + onset, out + onset + kept, out + length);
    std::fill(out + onset, out + std::min(length, onset + delay), 0.f);
  }
}

namespace {

/// The highest frequency a band's measurement sees: its octave's upper edge plus the masks'
/// crossover half-width (1/6 octave). Inner bands' masks end there anyway; the 8 kHz mask
/// reaches on to Nyquist, which its analysis filter does not see.
double measuredReach(int b) { return bandCentreExactHz(b) * std::exp2(0.5 + 1.0 / 6.0); }

using Coupling = std::array<std::array<double, kNumBands>, kNumBands>;

/// coupling[b][k]: what view M_b^2 sees of unit noise over band k, sum_f M_b^2 M_k^2, up to
/// b's measuredReach; masks on n-point FFT bins at sampleRate Hz.
Coupling viewCoupling(const OctaveBandMasks& masks, size_t n, int sampleRate) {
  Coupling coupling{};
  for (size_t i = 0; i < n / 2 + 1; ++i) {
    const double f = double(i) * sampleRate / double(n);
    for (int b = 0; b < kNumBands; ++b) {
      if (f > measuredReach(b)) continue;
      const double mb = double(masks.gain(b, i)) * masks.gain(b, i);
      for (int k = 0; k < kNumBands; ++k)
        coupling[size_t(b)][size_t(k)] += mb * masks.gain(k, i) * masks.gain(k, i);
    }
  }
  return coupling;
}

/// What each view M_b^2 sees of |H|^2 g^2 up to its measuredReach; spectrum on fft's bins
/// (fft.spec), sampleRate Hz.
std::array<double, kNumBands> viewEnergies(const FftwRealTransforms& fft, int sampleRate,
                                           const std::array<double, kNumBands>& rootEqualisation,
                                           const OctaveBandMasks& masks) {
  std::array<double, kNumBands> seen{}, m2{};
  for (size_t k = 0; k < fft.n / 2 + 1; ++k) {
    const double f = double(k) * sampleRate / double(fft.n);
    double g = 0.0;
    for (int b = 0; b < kNumBands; ++b) {
      m2[size_t(b)] = double(masks.gain(b, k)) * masks.gain(b, k);
      g += m2[size_t(b)] * rootEqualisation[size_t(b)];
    }
    const double h2 = (double(fft.spec.p[k][0]) * fft.spec.p[k][0] +
                       double(fft.spec.p[k][1]) * fft.spec.p[k][1]) * g * g;
    for (int b = 0; b < kNumBands; ++b)
      if (f <= measuredReach(b)) seen[size_t(b)] += m2[size_t(b)] * h2;
  }
  return seen;
}

/// u with coupling u = seen (Gaussian elimination without pivoting: the coupling is
/// diagonally dominant, a view holding mostly its own band).
Bands solveWeights(Coupling coupling, std::array<double, kNumBands> seen) {
  for (size_t i = 0; i < kNumBands; ++i)
    for (size_t r = i + 1; r < kNumBands; ++r) {
      const double q = coupling[r][i] / coupling[i][i];
      for (size_t k = i; k < kNumBands; ++k) coupling[r][k] -= q * coupling[i][k];
      seen[r] -= q * seen[i];
    }
  Bands u(0.f);
  for (size_t i = kNumBands; i-- > 0;) {
    double x = seen[i];
    for (size_t k = i + 1; k < kNumBands; ++k) x -= coupling[i][k] * u[int(k)];
    u[int(i)] = float(x / coupling[i][i]);
  }
  return u;
}

}  // namespace

std::vector<std::vector<Bands>> viewWeights(const std::vector<DirectionFilter>& filters,
                                            const std::vector<std::vector<Bands>>& weight,
                                            const std::array<double, kNumBands>& equalisation,
                                            const OctaveBandMasks& masks,
                                            FftwRealTransforms& fft, int sampleRate) {
  std::vector<std::vector<Bands>> out = weight;
  const Coupling coupling = viewCoupling(masks, fft.n, sampleRate);
  std::array<double, kNumBands> root{};
  for (int b = 0; b < kNumBands; ++b) root[size_t(b)] = std::sqrt(equalisation[size_t(b)]);
  for (size_t d = 0; d < filters.size(); ++d)
    for (size_t c = 0; c < filters[d].channels.size(); ++c) {
      const std::vector<float>& taps = filters[d].channels[c];
      if (taps.size() == 1) continue;
      std::fill(fft.time.p, fft.time.p + fft.n, 0.f);
      std::copy(taps.begin(), taps.end(), fft.time.p);
      fftwf_execute_dft_r2c(fft.fwd, fft.time.p, fft.spec.p);
      out[d][c] = solveWeights(coupling, viewEnergies(fft, sampleRate, root, masks));
    }
  return out;
}

}  // namespace dpc
