#include "engine/band_leveller.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "engine/fftw_util.h"
#include "engine/ir_synthesis.h"

namespace dpc {

struct BandLeveller::Fft {
  size_t nfft;
  FftwArray<float> time;
  FftwArray<fftwf_complex> spec, band;
  fftwf_plan fwd = nullptr, inv = nullptr;
  explicit Fft(size_t n) : nfft(n), time(n), spec(n / 2 + 1), band(n / 2 + 1) {
    fwd = fftwf_plan_dft_r2c_1d(int(n), time.p, spec.p, FFTW_ESTIMATE);
    inv = fftwf_plan_dft_c2r_1d(int(n), band.p, time.p, FFTW_ESTIMATE);
    if (!fwd || !inv) {
      if (fwd) fftwf_destroy_plan(fwd);
      if (inv) fftwf_destroy_plan(inv);
      throw std::runtime_error("BandLeveller: FFTW plan failed");
    }
  }
  ~Fft() {
    fftwf_destroy_plan(fwd);
    fftwf_destroy_plan(inv);
  }
  Fft(const Fft&) = delete;
  Fft& operator=(const Fft&) = delete;
};

BandLeveller::~BandLeveller() = default;

size_t BandLeveller::densityStart(int sampleRate, double roomVolume, double speedOfSound,
                                  double pulses) {
  // mu(t) = 4 pi c^3 t^2 / V >= pulses per bin
  const double mu = pulses / kBinSeconds;
  return size_t(std::sqrt(mu * roomVolume /
                          (4.0 * std::numbers::pi * speedOfSound * speedOfSound * speedOfSound)) *
                sampleRate);
}

BandLeveller::BandLeveller(int sampleRate, size_t length, int firstBand, size_t startSample)
    : sampleRate_(sampleRate), length_(length), firstBand_(firstBand), start_(startSample) {
  if (sampleRate <= 0 || length == 0 || firstBand < 0 || firstBand >= kNumBands)
    throw std::invalid_argument("BandLeveller: rate, length and first band must be valid");
  const size_t margin = size_t(sampleRate / 4);  // the zero-phase filters' reach
  fft_ = std::make_unique<Fft>(nextPow2(length + margin));
  const size_t nfft = fft_->nfft, nbins = nfft / 2 + 1;
  const OctaveBandMasks masks(sampleRate, nfft);
  const float scale = 1.f / float(nfft);
  binSamples_ = std::max<size_t>(1, size_t(std::lround(kBinSeconds * sampleRate)));
  const size_t bins = (length + binSamples_ - 1) / binSamples_;
  const size_t centre = margin / 2;
  std::vector<float> impulse(margin);
  for (int b = firstBand; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    target_[bi].assign(bins, 0.0);
    auto& f = filter_[bi];
    f.resize(nbins);
    for (size_t k = 0; k < nbins; ++k) f[k] = masks.gain(b, k) * masks.gain(b, k) * scale;
    const double fc = bandCentreExactHz(b);
    analysed_[bi] = fc * std::numbers::sqrt2 < 0.5 * sampleRate;
    if (!analysed_[bi]) continue;
    analysis_[bi] = OctaveBandPass::design(fc, sampleRate);
    // a_b (zero phase, time 0 at `centre`) through the analysis filter: its energy x the
    // white density per unit band energy.
    for (size_t k = 0; k < nbins; ++k) {
      fft_->band.p[k][0] = f[k];
      fft_->band.p[k][1] = 0.f;
    }
    fftwf_execute(fft_->inv);
    for (size_t i = 0; i < margin; ++i) impulse[i] = fft_->time.p[(i + nfft - centre) % nfft];
    OctaveBandPass::State st{};
    double e = 0.0;
    for (size_t n = 0; n < margin + size_t(sampleRate / 4); ++n) {
      const double y = analysis_[bi].step(n < margin ? impulse[n] : 0.f, st);
      e += y * y;
    }
    analysedPerOctave_[bi] = e * 0.5 * sampleRate / (fc / std::numbers::sqrt2);
  }
  actual_.assign(bins, 0.0);
  gain_.assign(bins, 1.f);
  part_.assign(length, 0.f);
}

void BandLeveller::clearTargets() {
  for (int b = firstBand_; b < kNumBands; ++b)
    std::fill(target_[size_t(b)].begin(), target_[size_t(b)].end(), 0.0);
  directSample_ = -1;
}

void BandLeveller::addResponse(const EnergyResponse& energy, const Bands& weight) {
  const double perBin = energy.binSeconds() * sampleRate_;
  const size_t nb = actual_.size();
  for (size_t k = 0; k < energy.binCount(); ++k) {
    const size_t j = std::min(nb - 1, size_t((double(k) + 0.5) * perBin) / binSamples_);
    for (int b = firstBand_; b < kNumBands; ++b)
      target_[size_t(b)][j] += double(std::max(0.f, energy.bins()[k][b])) * double(weight[b]);
  }
}

void BandLeveller::addDirect(double delaySeconds, const Bands& energy) {
  const long n0 = std::lround(delaySeconds * sampleRate_);
  if (n0 < 0 || size_t(n0) >= length_) return;
  directSample_ = n0;
  for (int b = firstBand_; b < kNumBands; ++b)
    target_[size_t(b)][size_t(n0) / binSamples_] += energy[b];
}

void BandLeveller::apply(float* ir, double tolerance, double maxBoost) {
  Fft& c = *fft_;
  std::fill(c.time.p, c.time.p + c.nfft, 0.f);
  std::copy(ir, ir + length_, c.time.p);
  fftwf_execute(c.fwd);
  const size_t nbins = c.nfft / 2 + 1;
  const size_t w = binSamples_;
  const size_t nb = actual_.size();
  const size_t half = kWindowBins / 2;
  for (int b = firstBand_; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    if (!analysed_[bi]) continue;
    const auto& target = target_[bi];
    // The first bin levelled: after the direct sound's (or the first target's) bin + 2 and
    // after the sequence is dense enough.
    size_t first = directSample_ >= 0 ? std::min(nb, size_t(directSample_) / w) : nb;
    for (size_t j = 0; j < first; ++j)
      if (target[j] > 0.0) {
        first = j;
        break;
      }
    first = std::max(first + 2, start_ / w + 1);
    if (first >= nb) continue;
    const auto& f = filter_[bi];
    for (size_t k = 0; k < nbins; ++k) {
      c.band.p[k][0] = c.spec.p[k][0] * f[k];
      c.band.p[k][1] = c.spec.p[k][1] * f[k];
    }
    fftwf_execute(c.inv);
    std::copy(c.time.p, c.time.p + length_, part_.begin());
    // What the band's analysis filter measures of the part: splatter sits mostly low in A_b's
    // span, inside the analysed octave, so A_b's reach up to Nyquist must not excuse it.
    std::fill(actual_.begin(), actual_.end(), 0.0);
    {
      OctaveBandPass::State st{};
      for (size_t n = 0; n < length_; ++n) {
        const double y = analysis_[bi].step(part_[n], st);
        actual_[n / w] += y * y;
        if (n % 64 == 63) OctaveBandPass::flushTiny(st);
      }
    }
    const double ratio = analysedPerOctave_[bi];
    bool any = false;
    for (size_t j = 0; j < nb; ++j) {
      gain_[j] = 1.f;
      if (j < first) continue;
      double want = 0.0, got = 0.0;
      for (size_t i = j >= half ? j - half : 0; i < std::min(nb, j + half + 1); ++i) {
        want += target[i];
        got += actual_[i];
      }
      const double high = tolerance * ratio * want;
      if (got > high) {
        gain_[j] = float(std::sqrt(high / got));
      } else if (maxBoost > 1.0 && got > 0.0 && got * tolerance < ratio * want) {
        gain_[j] = float(std::min(maxBoost, std::sqrt(ratio * want / (tolerance * got))));
      }
      any = any || gain_[j] != 1.f;
    }
    if (!any) continue;
    // ir += (g(n) - 1) part, g linear between bin centres (constant before the first and
    // after the last).
    for (size_t n = 0; n < length_; ++n) {
      const double x = (double(n) + 0.5) / double(w) - 0.5;
      double g;
      if (x <= 0.0) {
        g = gain_[0];
      } else if (x >= double(nb - 1)) {
        g = gain_[nb - 1];
      } else {
        const size_t j = size_t(x);
        const double t = x - double(j);
        g = (1.0 - t) * gain_[j] + t * gain_[j + 1];
      }
      if (g != 1.0) ir[n] += float((g - 1.0) * part_[n]);
    }
  }
}

}  // namespace dpc
