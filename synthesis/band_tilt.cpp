#include "synthesis/band_tilt.h"

#include <algorithm>
#include <cmath>

#include "synthesis/band_envelope.h"
#include "synthesis/pulse_energy.h"

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

TiltedBands::TiltedBands(int sampleRate, size_t length, const std::vector<float>& sequence,
                         const OctaveBandMasks& masks, FftwRealTransforms& fft,
                         const TiltedBands* shareScratch)
    : sampleRate_(sampleRate), length_(length) {
  if (shareScratch && shareScratch->length_ == length_) {
    tilted_ = shareScratch->tilted_;
  } else {
    tilted_ = std::make_shared<std::array<std::vector<float>, kNumBands>>();
    for (std::vector<float>& t : *tilted_) t.assign(length_, 0.f);
  }
  const size_t nfft = fft.n, nbins = nfft / 2 + 1;
  const float scale = 1.f / float(nfft);
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    for (size_t k = 0; k < nbins; ++k) {
      const float g = masks.gain(b, k) * masks.gain(b, k) * scale;
      fft.band.p[k][0] = fft.spec.p[k][0] * g;
      fft.band.p[k][1] = fft.spec.p[k][1] * g;
    }
    fftwf_execute(fft.inv);  // destroys fft.band, which is rebuilt each time
    band_[bi].assign(fft.time.p, fft.time.p + length_);
    const double fc = bandCentreExactHz(b);
    std::array<double, 3> half{};
    for (size_t k = 0; k < nbins; ++k) {
      const double a = double(masks.gain(b, k)) * masks.gain(b, k);
      const double p = powerAbove(double(k) * sampleRate / double(nfft), fc);
      const float g = float(a * p) * scale;
      fft.band.p[k][0] = fft.spec.p[k][0] * g;
      fft.band.p[k][1] = fft.spec.p[k][1] * g;
      // The band keeps its energy within its analysed octave, where the response's value
      // holds; the 63 Hz and 8 kHz bands' reach beyond follows with the same weights.
      if (!inAnalysedOctave(b, double(k) * sampleRate / double(nfft))) continue;
      half[0] += a * (1.0 - p) * a * (1.0 - p);
      half[1] += a * (1.0 - p) * a * p;
      half[2] += a * p * a * p;
    }
    halfEnergy_[bi] = half;
    fftwf_execute(fft.inv);
    upper_[bi].assign(fft.time.p, fft.time.p + length_);
    const size_t w = BandEnvelope::binSamplesFor(sampleRate, b);
    alpha_[bi].assign((length_ + w - 1) / w, 1.f);
    gamma_[bi].assign((length_ + w - 1) / w, 0.f);
    realised_[bi].assign((length_ + w - 1) / w, 0.0);
    expected_[bi].assign((length_ + w - 1) / w, 0.0);
  }
  // fft.spec keeps the sequence's spectrum (only fft.band and fft.time are used).
  for (int b = 0; b < kNumBands; ++b) pulseEnergies(b, sequence, masks, fft);
}

void TiltedBands::pulseEnergies(int b, const std::vector<float>& sequence,
                                const OctaveBandMasks& masks, FftwRealTransforms& fft) {
  const size_t nfft = fft.n, nbins = nfft / 2 + 1;
  const double fc = bandCentreExactHz(b);
  std::array<std::vector<float>, 2> h;  // A_b and A_b P, time 0 at index 0
  for (int part = 0; part < 2; ++part) {
    for (size_t k = 0; k < nbins; ++k) {
      const double a = double(masks.gain(b, k)) * masks.gain(b, k);
      const double p = part == 0 ? 1.0 : powerAbove(double(k) * sampleRate_ / double(nfft), fc);
      fft.band.p[k][0] = float(a * p / double(nfft));
      fft.band.p[k][1] = 0.f;
    }
    fftwf_execute(fft.inv);
    h[size_t(part)].assign(fft.time.p, fft.time.p + nfft);
  }
  // Taps beyond -70 dB each side change a bin's expectation by less than 1e-7.
  const TapSupport support = commonSupport(h[0], h[1], 1e-7);
  const CentredTaps lo = centredTaps(h[0], support), hi = centredTaps(h[1], support);
  const size_t w = BandEnvelope::binSamplesFor(sampleRate_, b);
  auto& e = pulseEnergy_[size_t(b)];
  e[0] = pulseEnergyPerBin(sequence, length_, w, lo, lo);
  e[1] = pulseEnergyPerBin(sequence, length_, w, lo, hi);
  e[2] = pulseEnergyPerBin(sequence, length_, w, hi, hi);
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
      const float* s = band_[bi].data();
      const float* sh = upper_[bi].data();
      float* t = (*tilted_)[bi].data();
      const float a = float(alpha), g = float(gamma);
      double realised = 0.0;
      for (size_t n = j * w; n < std::min(length_, (j + 1) * w); ++n) {
        t[n] = a * s[n] + g * sh[n];
        realised += double(t[n]) * double(t[n]);
      }
      realised_[bi][j] = realised;
      const auto& e = pulseEnergy_[bi];
      expected_[bi][j] =
          alpha * alpha * e[0][j] + 2.0 * alpha * gamma * e[1][j] + gamma * gamma * e[2][j];
    }
  }
}

}  // namespace dpc
