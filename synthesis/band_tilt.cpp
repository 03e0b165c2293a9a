#include "synthesis/band_tilt.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "synthesis/band_envelope.h"
#include "synthesis/pulse_energy.h"

namespace dpc {

namespace {

/// The response bins [k0, k1) of the kTiltWindowSeconds window centred on centreSeconds.
std::pair<size_t, size_t> tiltWindow(size_t bins, double binSeconds, double centreSeconds) {
  const double from = (centreSeconds - 0.5 * kTiltWindowSeconds) / binSeconds;
  const double to = (centreSeconds + 0.5 * kTiltWindowSeconds) / binSeconds;
  return {size_t(std::clamp(std::floor(from), 0.0, double(bins))),
          size_t(std::clamp(std::ceil(to), 0.0, double(bins)))};
}

/// The half-band densities from a window's energies in the octaves below, at and above band.
HalfBandDensity densityFromSums(int band, double below, double own, double above) {
  // Mean of exp(x L) over half an octave, x in [0, 1/2], L = ln(ratio): the log-linear
  // density's average over a half band relative to its value at the band centre,
  // (e^{L/2} - 1) / (L/2) with e^{L/2} = sqrt(ratio) (|L| clamped to kTiltMaxLog).
  auto halfMean = [](double ratio) {
    static const double lo = std::exp(-kTiltMaxLog), hi = std::exp(kTiltMaxLog);
    ratio = std::clamp(ratio, lo, hi);
    const double half = 0.5 * std::log(ratio);
    return std::abs(half) < 5e-7 ? 1.0 : (std::sqrt(ratio) - 1.0) / half;
  };
  HalfBandDensity r{1.0, 1.0};
  if (!(own > 0.0)) return r;
  // A band's value is its spectral density (band_filters.h), so the ratios compare directly.
  if (band > 0) r.low = halfMean(below / own);
  if (band + 1 < kNumBands) r.high = halfMean(above / own);
  return r;
}

}  // namespace

HalfBandDensity halfBandDensity(const EnergyResponse& energy, int band, double centreSeconds) {
  const auto [k0, k1] = tiltWindow(energy.binCount(), energy.binSeconds(), centreSeconds);
  double below = 0.0, own = 0.0, above = 0.0;
  for (size_t k = k0; k < k1; ++k) {
    const Bands& e = energy.bins()[k];
    own += std::max(0.f, e[band]);
    if (band > 0) below += std::max(0.f, e[band - 1]);
    if (band + 1 < kNumBands) above += std::max(0.f, e[band + 1]);
  }
  return densityFromSums(band, below, own, above);
}

void TiltWindowSums::reset(const EnergyResponse& energy) {
  binSeconds_ = energy.binSeconds();
  bins_ = energy.binCount();
  if (suffix_.size() < bins_ + 1) suffix_.resize(bins_ + 1);
  suffix_[bins_].fill(0.0);
  for (size_t k = bins_; k-- > 0;)
    for (int b = 0; b < kNumBands; ++b)
      suffix_[k][size_t(b)] =
          suffix_[k + 1][size_t(b)] + double(std::max(0.f, energy.bins()[k][b]));
  for (Last& l : last_) l.valid = false;
}

HalfBandDensity TiltWindowSums::at(int band, double centreSeconds) {
  // Plain variables, not a structured binding: the lambda below captures them (clang before
  // 16 refuses to capture bindings).
  const std::pair<size_t, size_t> window = tiltWindow(bins_, binSeconds_, centreSeconds);
  const size_t k0 = window.first, k1 = window.second;
  Last& last = last_[size_t(band)];
  if (last.valid && last.k0 == k0 && last.k1 == k1) return last.value;
  auto sum = [&](int b) {
    return b < 0 || b >= kNumBands ? 0.0 : suffix_[k0][size_t(b)] - suffix_[k1][size_t(b)];
  };
  last = {k0, k1, densityFromSums(band, sum(band - 1), sum(band), sum(band + 1)), true};
  return last.value;
}

std::shared_ptr<const TiltedBands::Filters> TiltedBands::makeFilters(
    int sampleRate, const OctaveBandMasks& masks, FftwRealTransforms& fft) {
  auto f = std::make_shared<Filters>();
  const size_t nfft = fft.n, nbins = nfft / 2 + 1;
  const float scale = 1.f / float(nfft);
  f->n = nfft;
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const double fc = bandCentreExactHz(b);
    f->band[bi].resize(nbins);
    f->upper[bi].resize(nbins);
    std::array<double, 3> half{};
    for (size_t k = 0; k < nbins; ++k) {
      const double a = double(masks.gain(b, k)) * masks.gain(b, k);
      const double p = powerAbove(double(k) * sampleRate / double(nfft), fc);
      f->band[bi][k] = float(a) * scale;  // a is exact: the float square, correctly rounded
      f->upper[bi][k] = float(a * p) * scale;
      // The band keeps its energy within its analysed octave, where the response's value
      // holds; the 63 Hz and 8 kHz bands' reach beyond follows with the same weights.
      if (!inAnalysedOctave(b, double(k) * sampleRate / double(nfft))) continue;
      half[0] += a * (1.0 - p) * a * (1.0 - p);
      half[1] += a * (1.0 - p) * a * p;
      half[2] += a * p * a * p;
    }
    f->half[bi] = half;
    if (b < kLevelledFromBand) continue;
    for (size_t k = 0; k < nbins; ++k) {
      fft.band.p[k][0] = f->band[bi][k];
      fft.band.p[k][1] = 0.f;
    }
    fftwf_execute(fft.inv);  // A_b's taps, time 0 at index 0
    const std::vector<float> h(fft.time.p, fft.time.p + nfft);
    // Taps beyond -70 dB each side change a bin's expectation by less than 1e-7.
    f->taps[bi] = centredTaps(h, commonSupport(h, h, 1e-7));
  }
  return f;
}

void TiltedBands::filterInto(const std::vector<float>& gain, FftwRealTransforms& fft,
                             std::vector<float>& out) const {
  const size_t nbins = fft.n / 2 + 1;
  for (size_t k = 0; k < nbins; ++k) {
    fft.band.p[k][0] = fft.spec.p[k][0] * gain[k];
    fft.band.p[k][1] = fft.spec.p[k][1] * gain[k];
  }
  fftwf_execute(fft.inv);  // destroys fft.band, which is rebuilt each time
  out.assign(fft.time.p, fft.time.p + length_);
}

TiltedBands::TiltedBands(int sampleRate, size_t length, const std::vector<float>& sequence,
                         const OctaveBandMasks& masks, FftwRealTransforms& fft,
                         const TiltedBands* shareScratch, Levelling levelling)
    : sampleRate_(sampleRate), length_(length) {
  if (shareScratch && shareScratch->length_ == length_) {
    tilted_ = shareScratch->tilted_;
  } else {
    tilted_ = std::make_shared<std::array<std::vector<float>, kNumBands>>();
    for (std::vector<float>& t : *tilted_) t.assign(length_, 0.f);
  }
  filters_ = shareScratch && shareScratch->filters_->n == fft.n
                 ? shareScratch->filters_
                 : makeFilters(sampleRate, masks, fft);
  const bool now = levelling == Levelling::kAtConstruction;
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    filterInto(filters_->band[bi], fft, band_[bi]);
    halfEnergy_[bi] = filters_->half[bi];
    // A band levelled now gets its upper half from the levelled sequence alone.
    if (!now || b < kLevelledFromBand) filterInto(filters_->upper[bi], fft, upper_[bi]);
    const size_t w = BandEnvelope::binSamplesFor(sampleRate, b);
    alpha_[bi].assign((length_ + w - 1) / w, 1.f);
    gamma_[bi].assign((length_ + w - 1) / w, 0.f);
  }
  if (!now) return;
  // fft.spec is restored to the sequence's spectrum after the levelling.
  const size_t nbins = fft.n / 2 + 1;
  std::vector<std::array<float, 2>> spectrum(nbins);
  for (size_t k = 0; k < nbins; ++k) spectrum[k] = {fft.spec.p[k][0], fft.spec.p[k][1]};
  level(sequence, fft);
  for (size_t k = 0; k < nbins; ++k) {
    fft.spec.p[k][0] = spectrum[k][0];
    fft.spec.p[k][1] = spectrum[k][1];
  }
}

void TiltedBands::level(const std::vector<float>& sequence, FftwRealTransforms& fft) {
  if (levelled_) return;
  // Each band's realisation to its expectation: the sequence's pulses are scaled per window
  // before the band filter, so the scaled signal stays within the band.
  for (int b = kLevelledFromBand; b < kNumBands; ++b) levelSequence(b, sequence, fft);
  levelled_ = true;
}

void TiltedBands::levelSequence(int b, const std::vector<float>& sequence,
                                FftwRealTransforms& fft) {
  const size_t bi = size_t(b), nfft = fft.n;
  const double fc = bandCentreExactHz(b);
  // Expected energy per bin of s_b over the pulses' signs, given their places and sizes.
  const CentredTaps& taps = filters_->taps[bi];
  const size_t w = BandEnvelope::binSamplesFor(sampleRate_, b);
  const std::vector<double> expected = pulseEnergyPerBin(sequence, length_, w, taps, taps);
  // Windows of whole bins, at least kLevellingPeriods periods of the band centre.
  const size_t perWindow = std::max<size_t>(
      1, size_t(std::ceil(kLevellingPeriods * sampleRate_ / fc / double(w) - 1e-9)));
  const size_t ww = perWindow * w, windows = (length_ + ww - 1) / ww;
  std::vector<double> want(windows, 0.0), factor(windows, 1.0);
  for (size_t j = 0; j < expected.size(); ++j) want[j / perWindow] += expected[j];
  const size_t n = std::min(length_, sequence.size());
  for (int it = 0; it < kSequenceLevelling; ++it) {
    const std::vector<float>& s = band_[bi];
    for (size_t i = 0; i < windows; ++i) {
      double realised = 0.0;
      for (size_t t = i * ww; t < std::min(length_, (i + 1) * ww); ++t)
        realised += double(s[t]) * double(s[t]);
      if (want[i] > 0.0 && realised > 0.0)
        factor[i] *=
            std::clamp(std::sqrt(want[i] / realised), 1.0 / kMaxSequenceFactor, kMaxSequenceFactor);
    }
    std::fill(fft.time.p, fft.time.p + nfft, 0.f);
    for (size_t t = 0; t < n; ++t) fft.time.p[t] = float(sequence[t] * factor[t / ww]);
    fftwf_execute(fft.fwd);
    filterInto(filters_->band[bi], fft, band_[bi]);
  }
  filterInto(filters_->upper[bi], fft, upper_[bi]);
}

void TiltedBands::update(const EnergyResponse& energy) {
  windows_.reset(energy);
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const size_t w = BandEnvelope::binSamplesFor(sampleRate_, b);
    const auto& [ll, lh, hh] = halfEnergy_[bi];
    for (size_t j = 0; j < alpha_[bi].size(); ++j) {
      const HalfBandDensity r = windows_.at(b, (double(j) + 0.5) * double(w) / sampleRate_);
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
      for (size_t n = j * w; n < std::min(length_, (j + 1) * w); ++n) t[n] = a * s[n] + g * sh[n];
    }
  }
}

}  // namespace dpc
