#include "synthesis/band_tilt.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "synthesis/band_envelope.h"

namespace dpc {

HalfBandDensity halfBandDensity(const EnergyResponse& energy, int band, double centreSeconds) {
  const size_t nk = energy.binCount();
  const double from = (centreSeconds - 0.5 * kTiltWindowSeconds) / energy.binSeconds();
  const double to = (centreSeconds + 0.5 * kTiltWindowSeconds) / energy.binSeconds();
  const size_t k0 = size_t(std::clamp(std::floor(from), 0.0, double(nk)));
  const size_t k1 = size_t(std::clamp(std::ceil(to), 0.0, double(nk)));
  double below = 0.0, own = 0.0, above = 0.0;
  for (size_t k = k0; k < k1; ++k) {
    const Bands& e = energy.bins()[k];
    own += std::max(0.f, e[band]);
    if (band > 0) below += std::max(0.f, e[band - 1]);
    if (band + 1 < kNumBands) above += std::max(0.f, e[band + 1]);
  }
  // Mean of exp(x L) over half an octave, x in [0, 1/2]: the log-linear density's average
  // over a half band, relative to its value at the band centre.
  auto halfMean = [](double l) {
    l = std::clamp(l, -kTiltMaxLog, kTiltMaxLog);
    return std::abs(l) < 1e-6 ? 1.0 : std::expm1(0.5 * l) / (0.5 * l);
  };
  HalfBandDensity r{1.0, 1.0};
  if (!(own > 0.0)) return r;
  // A band's value is its spectral density (band_filters.h), so the ratios compare directly.
  if (band > 0) r.low = halfMean(std::log(std::max(below / own, 1e-300)));
  if (band + 1 < kNumBands) r.high = halfMean(std::log(std::max(above / own, 1e-300)));
  return r;
}

namespace {

/// The sequence (whose spectrum fft.spec holds) through the real gain gainAt(k) on fft's bins
/// k, length samples.
template <typename Gain>
std::vector<float> filtered(FftwRealTransforms& fft, size_t length, Gain gainAt) {
  const size_t nfft = fft.n;
  for (size_t k = 0; k < nfft / 2 + 1; ++k) {
    const float g = float(gainAt(k)) / float(nfft);
    fft.band.p[k][0] = fft.spec.p[k][0] * g;
    fft.band.p[k][1] = fft.spec.p[k][1] * g;
  }
  fftwf_execute(fft.inv);  // destroys fft.band, which is rebuilt each time
  return std::vector<float>(fft.time.p, fft.time.p + length);
}

/// Amplitude share of band b's filter beyond its analysed octave at f Hz (below 44 Hz for the
/// 63 Hz band, above 11.3 kHz for the 8 kHz band; 0 for the inner bands): the crossover of
/// powerAbove at the octave's outer edge, so that the parts within and beyond add up to A_b.
double beyondShare(int b, double f) {
  const double fc = bandCentreExactHz(b);
  if (b == 0) return 1.0 - powerAbove(f, fc / std::numbers::sqrt2);
  if (b == kNumBands - 1) return powerAbove(f, fc * std::numbers::sqrt2);
  return 0.0;
}

}  // namespace

TiltedBands::TiltedBands(int sampleRate, size_t length, const OctaveBandMasks& masks,
                         FftwRealTransforms& fft)
    : sampleRate_(sampleRate), length_(length) {
  const size_t nfft = fft.n;
  auto freq = [&](size_t k) { return double(k) * sampleRate / double(nfft); };
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const double fc = bandCentreExactHz(b);
    auto a = [&](size_t k) { return double(masks.gain(b, k)) * masks.gain(b, k); };
    band_[bi] = filtered(fft, length, a);
    upper_[bi] = filtered(fft, length, [&](size_t k) { return a(k) * powerAbove(freq(k), fc); });
    if (b == 0 || b == kNumBands - 1) {
      const size_t e = b == 0 ? 0 : 1;
      beyondBand_[e] =
          filtered(fft, length, [&](size_t k) { return a(k) * beyondShare(b, freq(k)); });
      beyondUpper_[e] = filtered(fft, length, [&](size_t k) {
        return a(k) * powerAbove(freq(k), fc) * beyondShare(b, freq(k));
      });
      beyond_[e].assign(length_, 0.f);
    }
    halfEnergy_[bi] = halfEnergies(masks, b, nfft);
    tilted_[bi].assign(length_, 0.f);
    const size_t w = BandEnvelope::binSamplesFor(sampleRate, b);
    alpha_[bi].assign((length_ + w - 1) / w, 1.f);
    gamma_[bi].assign((length_ + w - 1) / w, 0.f);
  }
}

std::array<double, 3> TiltedBands::halfEnergies(const OctaveBandMasks& masks, int b,
                                                size_t nfft) const {
  // The band keeps its energy within its analysed octave, where the response's value holds;
  // the extreme bands' reach beyond follows with the same gains.
  std::array<double, 3> half{};
  for (size_t k = 0; k < nfft / 2 + 1; ++k) {
    const double f = double(k) * sampleRate_ / double(nfft);
    if (!inAnalysedOctave(b, f)) continue;
    const double a = double(masks.gain(b, k)) * masks.gain(b, k);
    const double p = powerAbove(f, bandCentreExactHz(b));
    half[0] += a * (1.0 - p) * a * (1.0 - p);
    half[1] += a * (1.0 - p) * a * p;
    half[2] += a * p * a * p;
  }
  return half;
}

void TiltedBands::update(const EnergyResponse& energy) {
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const size_t w = BandEnvelope::binSamplesFor(sampleRate_, b);
    const auto& [ll, lh, hh] = halfEnergy_[bi];
    for (size_t j = 0; j < alpha_[bi].size(); ++j) {
      const HalfBandDensity r =
          halfBandDensity(energy, b, (double(j) + 0.5) * double(w) / sampleRate_);
      const double pl = std::sqrt(r.low), ph = std::sqrt(r.high);
      // Same expected energy as the untilted s_b = s_lo + s_hi.
      const double norm =
          std::sqrt((ll + 2.0 * lh + hh) / (r.low * ll + 2.0 * pl * ph * lh + r.high * hh));
      const double alpha = pl * norm, gamma = ph * norm - alpha;
      alpha_[bi][j] = float(alpha);
      gamma_[bi][j] = float(gamma);
      const size_t lo = j * w, hi = std::min(length_, (j + 1) * w);
      tilt(band_[bi], upper_[bi], float(alpha), float(gamma), lo, hi, tilted_[bi]);
      if (b == 0 || b == kNumBands - 1) {
        const size_t e = b == 0 ? 0 : 1;
        tilt(beyondBand_[e], beyondUpper_[e], float(alpha), float(gamma), lo, hi, beyond_[e]);
      }
    }
  }
}

void TiltedBands::tilt(const std::vector<float>& s, const std::vector<float>& sh, float alpha,
                       float gamma, size_t lo, size_t hi, std::vector<float>& out) {
  for (size_t n = lo; n < hi; ++n) out[n] = alpha * s[n] + gamma * sh[n];
}

}  // namespace dpc
