#include "synthesis/band_filters.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dpc {

namespace {

/// sum_k M_b^2 A_bi A_bj over the FFT bins (bi, bj valid bands).
double couplingSum(const OctaveBandMasks& masks, int b, int bi, int bj) {
  double c = 0.0;
  for (size_t k = 0; k < masks.binCount(); ++k) {
    const double m2 = double(masks.gain(b, k)) * masks.gain(b, k);
    c += m2 * double(masks.gain(bi, k)) * masks.gain(bi, k) * double(masks.gain(bj, k)) *
         masks.gain(bj, k);
  }
  return c;
}

}  // namespace

BandFilterData BandFilterData::compute(const OctaveBandMasks& masks, size_t fftSize) {
  BandFilterData d;
  const size_t nbins = masks.binCount();
  for (int b = 0; b < kNumBands; ++b) {
    double norm = 0.0, share = 0.0;
    for (size_t k = 0; k < nbins; ++k) {
      const double m2 = double(masks.gain(b, k)) * masks.gain(b, k);
      norm += m2;
      share += ((k == 0 || k == nbins - 1) ? 1.0 : 2.0) * m2 / double(fftSize);
    }
    d.share[size_t(b)] = share;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int bi = b + i - 1, bj = b + j - 1;
        if (bi < 0 || bj < 0 || bi >= kNumBands || bj >= kNumBands) continue;
        d.coupling[size_t(b)][size_t(i)][size_t(j)] = couplingSum(masks, b, bi, bj) / norm;
      }
  }
  return d;
}

void mergeCoincidentArrivals(std::vector<Arrival>& arrivals, int sampleRate) {
  auto sample = [&](const Arrival& a) { return std::lround(a.delaySeconds * sampleRate); };
  std::sort(arrivals.begin(), arrivals.end(),
            [](const Arrival& a, const Arrival& b) { return a.delaySeconds < b.delaySeconds; });
  size_t out = 0;
  for (size_t i = 0; i < arrivals.size();) {
    Bands amplitude(0.f);
    size_t j = i;
    for (; j < arrivals.size() && sample(arrivals[j]) == sample(arrivals[i]); ++j)
      for (int b = 0; b < kNumBands; ++b)
        amplitude[b] += std::sqrt(std::max(0.f, arrivals[j].intensity[b]));
    arrivals[out] = arrivals[i];
    for (int b = 0; b < kNumBands; ++b) arrivals[out].intensity[b] = amplitude[b] * amplitude[b];
    ++out;
    i = j;
  }
  arrivals.resize(out);
}

size_t cutLeadingResidue(std::span<float* const> channels, size_t length, size_t onset,
                         int sampleRate) {
  const size_t end = std::min(length, onset + size_t(sampleRate / 1000));
  double reference = 0.0;
  for (const float* x : channels)
    for (size_t n = 0; n < end; ++n) reference += double(x[n]) * double(x[n]);
  const double allowed = reference * kLeadingResidueEnergy;
  double cut = 0.0;
  size_t count = 0;
  for (; count < end; ++count) {
    double e = 0.0;
    for (const float* x : channels) e += double(x[count]) * double(x[count]);
    if (cut + e > allowed) break;
    cut += e;
  }
  for (float* x : channels) std::fill(x, x + count, 0.f);
  return count;
}

DirectSoundFilter::DirectSoundFilter(const OctaveBandMasks& masks, FftwRealTransforms& fft,
                                     size_t taps)
    : centre_(taps / 2) {
  const size_t nfft = fft.n, nbins = nfft / 2 + 1;
  const float scale = 1.f / float(nfft);
  for (int b = 0; b < kNumBands; ++b) {
    for (size_t k = 0; k < nbins; ++k) {
      fft.band.p[k][0] = masks.gain(b, k) * masks.gain(b, k) * scale;
      fft.band.p[k][1] = 0.f;
    }
    fftwf_execute(fft.inv);
    // Rotated so that index centre_ is time 0.
    filter_[size_t(b)].assign(taps, 0.f);
    for (size_t i = 0; i < taps; ++i)
      filter_[size_t(b)][i] = fft.time.p[(i + nfft - centre_) % nfft];
    support_[size_t(b)] = supportOf(filter_[size_t(b)]);
  }
}

std::pair<size_t, size_t> DirectSoundFilter::supportOf(const std::vector<float>& h) {
  double total = 0.0;
  for (float x : h) total += double(x) * double(x);
  const double tail = total * kNegligibleTailEnergy;
  size_t begin = 0, end = h.size();
  for (double cut = 0.0; begin < end;) {  // drop leading taps while their energy is negligible
    cut += double(h[begin]) * double(h[begin]);
    if (cut > tail) break;
    ++begin;
  }
  for (double cut = 0.0; end > begin;) {
    cut += double(h[end - 1]) * double(h[end - 1]);
    if (cut > tail) break;
    --end;
  }
  return {begin, end};
}

void DirectSoundFilter::add(int b, float amplitude, long start, float* out, size_t length) const {
  const auto& h = filter_[size_t(b)];
  const auto [begin, end] = support_[size_t(b)];
  const long first = std::max(long(begin), -start);
  const long last = std::min(long(end), long(length) - start);
  for (long i = first; i < last; ++i) out[start + i] += amplitude * h[size_t(i)];
}

}  // namespace dpc
