// Helpers shared by the engine and app tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <utility>
#include <vector>

#include "common/fftw_util.h"
#include "engine/energy_response.h"
#include "engine/propagation.h"
#include "synthesis/band_filters.h"

namespace dpc::test {

/// Mean of v and its standard error (sample standard deviation / sqrt(n)); v.size() >= 2.
inline std::pair<double, double> meanAndStandardError(const std::vector<double>& v) {
  double m = 0.0, s = 0.0;
  for (double x : v) m += x;
  m /= double(v.size());
  for (double x : v) s += (x - m) * (x - m);
  return {m, std::sqrt(s / double(v.size() - 1) / double(v.size()))};
}

/// A trace of the settings' rays and seed from `origin` (source `emitter`) in frame `frame`,
/// tested against `receivers` (which must outlive the request).
inline TraceRequest traceRequest(const PropagationSettings& ps, uint64_t frame, uint32_t emitter,
                                 const glm::vec3& origin,
                                 std::span<const ListenerSphere> receivers) {
  TraceRequest rq;
  rq.seed = ps.seed;
  rq.frame = frame;
  rq.emitter = emitter;
  rq.origin = origin;
  rq.rays = ps.raysPerFrame;
  rq.receivers = receivers;
  return rq;
}

/// Bit-for-bit equality of two energy responses.
inline bool identical(const EnergyResponse& a, const EnergyResponse& b) {
  return a.binCount() == b.binCount() &&
         std::memcmp(a.bins().data(), b.bins().data(), a.binCount() * sizeof(Bands)) == 0;
}

/// Band levels of x on the energy response's scale: per band, the energy of x through the
/// synthesiser's power-complementary octave mask M_b (Parseval on one real FFT) divided by
/// what a unit impulse gives through it, so a Dirac of energy E reads E in every band and a
/// response's band value (a spectral density, synthesis/band_filters.h) reads as itself.
/// analysedOctaves: the 63 Hz and 8 kHz bands count only their octave (fc / sqrt 2 .. fc sqrt 2),
/// as an octave-band analysis does, not their masks' reach down to 0 Hz and up to Nyquist.
/// Lag (seconds) of the peak of the cross-correlation right vs left: > 0 when the right ear
/// hears the sound later.
inline double interauralDelay(const std::vector<float>& l, const std::vector<float>& r, int fs) {
  const int maxLag = fs / 500;  // +-2 ms
  double best = -1e300;
  int bestLag = 0;
  for (int lag = -maxLag; lag <= maxLag; ++lag) {
    double c = 0.0;
    for (size_t n = 0; n < l.size(); ++n) {
      const long m = long(n) + lag;
      if (m >= 0 && m < long(r.size())) c += double(l[n]) * r[size_t(m)];
    }
    if (c > best) best = c, bestLag = lag;
  }
  return double(bestLag) / fs;
}

inline Bands bandEnergies(const std::vector<float>& x, int fs, bool analysedOctaves = false) {
  size_t n = 1;
  while (n < 2 * x.size()) n <<= 1;
  FftwRealTransforms fft(n);
  std::fill(fft.time.p, fft.time.p + n, 0.f);
  std::copy(x.begin(), x.end(), fft.time.p);
  fftwf_execute(fft.fwd);
  const fftwf_complex* out = fft.spec.p;
  OctaveBandMasks masks(fs, n);
  std::array<double, kNumBands> e{}, unit{};
  for (size_t k = 0; k <= n / 2; ++k) {
    const double mag2 = double(out[k][0]) * out[k][0] + double(out[k][1]) * out[k][1];
    const double w = (k == 0 || k == n / 2) ? 1.0 : 2.0;  // one-sided spectrum
    const double f = double(k) * fs / double(n);
    for (int b = 0; b < kNumBands; ++b) {
      if (analysedOctaves && ((b == 0 && f < bandCentreExactHz(b) / std::numbers::sqrt2) ||
                              (b == kNumBands - 1 && f > bandCentreExactHz(b) * std::numbers::sqrt2)))
        continue;
      const double g = masks.gain(b, k);
      e[size_t(b)] += w * g * g * mag2 / double(n);
      unit[size_t(b)] += w * g * g / double(n);
    }
  }
  Bands levels(0.f);
  for (int b = 0; b < kNumBands; ++b) levels[b] = float(e[size_t(b)] / unit[size_t(b)]);
  return levels;
}

}  // namespace dpc::test
