#include "synthesis/arrival_placer.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <mutex>
#include <numbers>
#include <stdexcept>

namespace dpc {

ArrivalPlacer::ArrivalPlacer(const OctaveBandMasks& masks,
                             std::shared_ptr<const DirectSoundFilter> direct, size_t fftSize)
    : direct_(std::move(direct)), n_(fftSize), spec_(fftSize / 2 + 1) {
  if (n_ < 2 || masks.binCount() != n_ / 2 + 1)
    throw std::invalid_argument("ArrivalPlacer: the FFT size must be the masks'");
  chooseSplit(masks);
  const size_t coarse = n_ / kFine + 1;
  coarse_.resize(2 * coarse);
  fine_.resize(2 * kFine);
  const double w = -2.0 * std::numbers::pi / double(n_);
  for (size_t h = 0; h < coarse; ++h) {
    coarse_[2 * h] = float(std::cos(w * double(h * kFine)));
    coarse_[2 * h + 1] = float(std::sin(w * double(h * kFine)));
  }
  for (size_t l = 0; l < kFine; ++l) {
    fine_[2 * l] = float(std::cos(w * double(l)));
    fine_[2 * l + 1] = float(std::sin(w * double(l)));
  }
  float* const spec = reinterpret_cast<float*>(spec_.p);
  std::fill(spec, spec + 2 * (n_ / 2 + 1), 0.f);
  std::lock_guard<std::mutex> lock(fftwPlannerMutex());
  inverse_ = fftwf_plan_dft_c2r_1d(int(n_), spec_.p, reinterpret_cast<float*>(spec_.p),
                                   FFTW_ESTIMATE);
  if (!inverse_) throw std::runtime_error("ArrivalPlacer: FFTW plan failed");
}

ArrivalPlacer::~ArrivalPlacer() {
  std::lock_guard<std::mutex> lock(fftwPlannerMutex());
  fftwf_destroy_plan(inverse_);
}

void ArrivalPlacer::chooseSplit(const OctaveBandMasks& masks) {
  // bins(F): one past the last bin where a band below F has any gain.
  std::array<size_t, kNumBands + 1> binsBelow{};
  for (int b = 0; b < kNumBands; ++b) {
    size_t last = 0;
    for (size_t k = 0; k < masks.binCount(); ++k)
      if (masks.gain(b, k) > 0.f) last = k + 1;
    binsBelow[size_t(b) + 1] = std::max(binsBelow[size_t(b)], last);
  }
  double best = -1.0;
  for (int f = 0; f <= kNumBands; ++f) {
    double cost = double(binsBelow[size_t(f)]) * kBinCost;
    for (int b = f; b < kNumBands; ++b) cost += double(direct_->support(b));
    if (best < 0.0 || cost < best) best = cost, split_ = f, bins_ = binsBelow[size_t(f)];
  }
  const size_t padded = (bins_ + 3) / 4 * 4;
  lowGain_.assign(padded, 0.f);
  highGain_.assign(padded, 0.f);
  gain_.assign(padded, 0.f);
  accRe_.assign(padded, 0.f);
  accIm_.assign(padded, 0.f);
  bandStart_.assign(size_t(split_) + 1, bins_);
  if (split_ > 0) bandStart_[0] = 0;
  for (size_t k = 0; k < bins_; ++k) {
    int b = 0;  // the lowest band below the split with gain here (the masks are contiguous)
    while (b + 1 < split_ && masks.gain(b, k) == 0.f) ++b;
    for (int c = b; c > 0 && bandStart_[size_t(c)] > k; --c) bandStart_[size_t(c)] = k;
    lowGain_[k] = masks.gain(b, k) * masks.gain(b, k);
    if (b + 1 < split_) highGain_[k] = masks.gain(b + 1, k) * masks.gain(b + 1, k);
  }
}

void ArrivalPlacer::twiddle(size_t m, float& re, float& im) const {
  const float* c = &coarse_[2 * (m / kFine)];
  const float* f = &fine_[2 * (m % kFine)];
  re = c[0] * f[0] - c[1] * f[1];
  im = c[0] * f[1] + c[1] * f[0];
}

void ArrivalPlacer::addToSpectrum(const Arrival& a, long n0) {
  using V4 = float __attribute__((vector_size(16)));
  // amp[b] for b < split, and 0 past it (a bin's upper band may be the split itself).
  std::array<float, kNumBands + 1> amp{};
  for (int b = 0; b < split_; ++b)
    amp[size_t(b)] = float(std::sqrt(std::max(0.0, double(a.intensity[b]))));
  float* __restrict gain = gain_.data();
  const float* __restrict low = lowGain_.data();
  const float* __restrict high = highGain_.data();
  for (int b = 0; b < split_; ++b) {
    const float a0 = amp[size_t(b)], a1 = amp[size_t(b) + 1];
    for (size_t k = bandStart_[size_t(b)]; k < bandStart_[size_t(b) + 1]; ++k)
      gain[k] = a0 * low[k] + a1 * high[k];
  }
  float* __restrict accRe = accRe_.data();
  float* __restrict accIm = accIm_.data();
  // kChains independent recurrences of four bins each (bins k0 + 4 c + j), so that the
  // multiplies of one do not wait for the last: each steps by kChains x 4 bins.
  constexpr size_t kChains = 4, kStride = 4 * kChains;
  const size_t step = size_t(((n0 % long(n_)) + long(n_)) % long(n_));
  float wr, wi;
  twiddle((kStride * step) % n_, wr, wi);
  const size_t padded = gain_.size();
  for (size_t k0 = 0; k0 < padded; k0 += kSeedBins) {
    V4 zr[kChains], zi[kChains];
    for (size_t j = 0; j < kStride; ++j) {
      float r, i;  // a vector lane cannot bind to a reference (clang)
      twiddle(((k0 + j) * step) % n_, r, i);
      zr[j / 4][j % 4] = r;
      zi[j / 4][j % 4] = i;
    }
    const size_t end = std::min(k0 + kSeedBins, padded);
    for (size_t k = k0; k < end; k += kStride)
      for (size_t c = 0; c < kChains && k + 4 * c < end; ++c) {
        const size_t i = k + 4 * c;
        V4 g, re, im;
        std::memcpy(&g, gain + i, sizeof g);
        std::memcpy(&re, accRe + i, sizeof re);
        std::memcpy(&im, accIm + i, sizeof im);
        re += g * zr[c];
        im += g * zi[c];
        std::memcpy(accRe + i, &re, sizeof re);
        std::memcpy(accIm + i, &im, sizeof im);
        const V4 next = zr[c] * wr - zi[c] * wi;
        zi[c] = zr[c] * wi + zi[c] * wr;
        zr[c] = next;
      }
  }
}

void ArrivalPlacer::addSpectrumToIr(float* ir, size_t length) {
  for (size_t k = 0; k < bins_; ++k) {
    spec_.p[k][0] = accRe_[k];
    spec_.p[k][1] = accIm_[k];
  }
  std::fill(accRe_.begin(), accRe_.end(), 0.f);
  std::fill(accIm_.begin(), accIm_.end(), 0.f);
  fftwf_execute(inverse_);
  const float* time = reinterpret_cast<const float*>(spec_.p);
  const float scale = 1.f / float(n_);
  for (size_t i = 0; i < length; ++i) ir[i] += time[i] * scale;
  float* const spec = reinterpret_cast<float*>(spec_.p);
  std::fill(spec, spec + 2 * (n_ / 2 + 1), 0.f);
}

void ArrivalPlacer::place(std::span<const Arrival> arrivals, int sampleRate, float* ir,
                          size_t length) {
  assert(length + direct_->taps() <= n_);
  const long centre = long(direct_->centre());
  bool spectrum = false;
  for (const Arrival& a : arrivals) {
    const long n0 = std::lround(a.delaySeconds * sampleRate);
    if (n0 <= -centre || n0 >= long(length) + centre) continue;  // its pulse misses the IR
    for (int b = split_; b < kNumBands; ++b) {
      const float amp = float(std::sqrt(std::max(0.0, double(a.intensity[b]))));
      direct_->add(b, amp, n0 - centre, ir, length);
    }
    if (split_ > 0) addToSpectrum(a, n0), spectrum = true;
  }
  if (spectrum) addSpectrumToIr(ir, length);
}

}  // namespace dpc
