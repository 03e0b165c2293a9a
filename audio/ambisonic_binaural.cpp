#include "audio/ambisonic_binaural.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "common/bands.h"
#include "common/fftw_util.h"
#include "common/octave_band_masks.h"
#include "common/spherical_harmonics.h"

namespace dpc::audio {

namespace {

/// Power spectrum p[0 .. n/2] smoothed over a third of an octave around each bin (bin 0 and
/// bins below 1/3 octave's width average with their neighbours down to bin 1).
std::vector<double> thirdOctaveSmoothed(const std::vector<double>& p) {
  const double half = std::pow(2.0, 1.0 / 6.0);
  std::vector<double> prefix(p.size() + 1, 0.0);
  for (size_t k = 0; k < p.size(); ++k) prefix[k + 1] = prefix[k] + p[k];
  std::vector<double> out(p.size());
  for (size_t k = 0; k < p.size(); ++k) {
    const double centre = std::max(1.0, double(k));
    const size_t lo = std::max<size_t>(1, size_t(std::floor(centre / half)));
    const size_t hi = std::min(p.size() - 1, std::max(lo, size_t(std::ceil(centre * half))));
    out[k] = (prefix[hi + 1] - prefix[lo]) / double(hi + 1 - lo);
  }
  return out;
}

/// The equaliser's magnitude on the bins of p (p[0 .. n/2], n = 2 (p.size() - 1), the decoder's
/// diffuse-field power): E = sum_b A_b g_b, A_b = M_b^2 the amplitude-complementary octave-band
/// filters. In the directional bands (kDirectionalFromBand up, where per-path binaural levels
/// HRIRs per band) g_b = 1 / sqrt(D_b), D_b the A_b-weighted mean of p over band b's analysed
/// octave (a band measurement, as the spatial synthesiser levels its filters); in the lower
/// bands, which per-path binaural renders without HRIRs, g_b(f) = 1 / sqrt(p smoothed over a
/// third octave at f), flattening the HRTF's steep low-frequency roll-off within the band.
/// Every gain at most maxGain.
std::vector<double> diffuseFieldEqualiser(const std::vector<double>& p, int sampleRate,
                                          double maxGain) {
  const size_t bins = p.size(), n = 2 * (bins - 1);
  const OctaveBandMasks masks(sampleRate, n);
  const std::vector<double> smooth = thirdOctaveSmoothed(p);
  std::array<double, kNumBands> gain{};
  for (int b = kDirectionalFromBand; b < kNumBands; ++b) {
    double power = 0.0, weight = 0.0;
    for (size_t k = 1; k < bins; ++k) {
      if (!inAnalysedOctave(b, double(k) * sampleRate / double(n))) continue;
      const double a = double(masks.gain(b, k)) * masks.gain(b, k);
      power += a * p[k];
      weight += a;
    }
    gain[size_t(b)] = power > 0.0 ? std::min(maxGain, std::sqrt(weight / power)) : maxGain;
  }
  std::vector<double> mag(bins, 0.0);
  for (size_t k = 0; k < bins; ++k) {
    const double fine = smooth[k] > 0.0 ? std::min(maxGain, 1.0 / std::sqrt(smooth[k])) : maxGain;
    for (int b = 0; b < kNumBands; ++b)
      mag[k] += double(masks.gain(b, k)) * masks.gain(b, k) *
                (b < kDirectionalFromBand ? fine : gain[size_t(b)]);
  }
  return mag;
}

/// The minimum-phase filter of magnitude mag[0 .. n/2] (n = fft.n), its first `taps` taps
/// faded out over the last quarter: log-magnitude -> real cepstrum -> fold onto positive
/// quefrencies -> exp of its spectrum.
std::vector<float> minimumPhase(FftwRealTransforms& fft, const std::vector<double>& mag,
                                size_t taps) {
  const size_t n = fft.n, bins = n / 2 + 1;
  for (size_t k = 0; k < bins; ++k) {
    fft.band.p[k][0] = float(std::log(std::max(mag[k], 1e-12)));
    fft.band.p[k][1] = 0.f;
  }
  fftwf_execute(fft.inv);  // band -> time: the real cepstrum times n
  for (size_t m = 1; m < n / 2; ++m) fft.time.p[m] *= 2.f;
  for (size_t m = n / 2 + 1; m < n; ++m) fft.time.p[m] = 0.f;
  for (size_t m = 0; m < n; ++m) fft.time.p[m] /= float(n);
  fftwf_execute(fft.fwd);  // time -> spec: the minimum-phase log spectrum
  for (size_t k = 0; k < bins; ++k) {
    const double a = std::exp(double(fft.spec.p[k][0])), phi = fft.spec.p[k][1];
    fft.band.p[k][0] = float(a * std::cos(phi));
    fft.band.p[k][1] = float(a * std::sin(phi));
  }
  fftwf_execute(fft.inv);
  std::vector<float> h(taps);
  const size_t fade = taps / 4;
  for (size_t t = 0; t < taps; ++t) {
    const double w =
        t + fade < taps
            ? 1.0
            : 0.5 + 0.5 * std::cos(std::numbers::pi * double(t + fade - taps + 1) / double(fade));
    h[t] = float(w * fft.time.p[t] / double(n));
  }
  return h;
}

/// The virtual-loudspeaker sampling decoder's filters (see the header), `length` taps each.
ChannelEarFilters samplingFilters(int order, const Hrtf& hrtf, size_t length) {
  const size_t nc = size_t(ambisonicChannels(order)), taps = size_t(hrtf.filterLength());
  const int nz = order + 2, nphi = 2 * order + 4;
  std::vector<double> zs(static_cast<size_t>(nz)), ws(static_cast<size_t>(nz));
  for (int k = 0; k < nz; ++k) gaussLegendreNode(nz, k, zs[size_t(k)], ws[size_t(k)]);
  ChannelEarFilters filters(nc, {std::vector<float>(length, 0.f), std::vector<float>(length, 0.f)});
  std::vector<float> ear[2] = {std::vector<float>(taps), std::vector<float>(taps)};
  std::array<float, ambisonicChannels(kMaxAmbisonicOrder)> y{};
  for (size_t k = 0; k < zs.size(); ++k)
    for (int j = 0; j < nphi; ++j) {
      const double phi = 2.0 * std::numbers::pi * double(j) / double(nphi);
      const double s = std::sqrt(1.0 - zs[k] * zs[k]);
      const float u[3] = {float(s * std::cos(phi)), float(s * std::sin(phi)), float(zs[k])};
      float delay[2] = {0.f, 0.f};
      hrtf.hrir(u, ear[0].data(), ear[1].data(), &delay[0], &delay[1]);
      sphericalHarmonicsSn3d(order, u, y);
      const double w = ws[k] * (2.0 * std::numbers::pi / double(nphi)) / (4.0 * std::numbers::pi);
      for (int n = 0; n <= order; ++n)
        for (int c = n * n; c < (n + 1) * (n + 1); ++c)
          for (int e = 0; e < 2; ++e) {
            const float g = float(w * double(2 * n + 1) * y[size_t(c)]);
            const size_t d = std::min(size_t(std::max(0.f, std::round(delay[e]))), length - taps);
            float* f = filters[size_t(c)][size_t(e)].data() + d;
            for (size_t t = 0; t < taps; ++t) f[t] += g * ear[e][t];
          }
    }
  return filters;
}

}  // namespace

AmbisonicBinauralDecoder::AmbisonicBinauralDecoder(int order, const Hrtf& hrtf,
                                                   const BinauralDecoderOptions& options)
    : order_(std::clamp(order, 1, kMaxAmbisonicOrder)), method_(options.method) {
  length_ = size_t(hrtf.filterLength()) + size_t(hrtf.sampleRate() / 500);  // onsets up to 2 ms
  filters_ = method_ == BinauralDecoderMethod::kSampling
                 ? samplingFilters(order_, hrtf, length_)
                 : magLsFilters(order_, hrtf, options.magLs, length_);
  equaliseDiffuseField(hrtf.sampleRate());
}

void AmbisonicBinauralDecoder::equaliseDiffuseField(int sampleRate) {
  const size_t n = 4 * kEqualiserTaps, bins = n / 2 + 1;
  FftwRealTransforms fft(n);
  std::vector<double> power(bins, 0.0);
  for (int order = 0; order <= order_; ++order)
    for (int c = order * order; c < (order + 1) * (order + 1); ++c)
      for (int e = 0; e < 2; ++e) {
        const std::vector<float>& f = filters_[size_t(c)][size_t(e)];
        std::fill(fft.time.p, fft.time.p + n, 0.f);
        std::copy(f.begin(), f.end(), fft.time.p);
        fftwf_execute(fft.fwd);
        for (size_t k = 0; k < bins; ++k)
          power[k] += (double(fft.spec.p[k][0]) * fft.spec.p[k][0] +
                       double(fft.spec.p[k][1]) * fft.spec.p[k][1]) /
                      double(2 * order + 1) / 2.0;
      }
  const double maxGain = std::pow(10.0, kMaxEqualiserBoostDb / 20.0);
  equaliser_ = minimumPhase(fft, diffuseFieldEqualiser(power, sampleRate, maxGain), kEqualiserTaps);
}

void AmbisonicBinauralDecoder::decode(const float* const* channels, size_t n, float* left,
                                      float* right) const {
  std::vector<float> ears[2] = {std::vector<float>(n, 0.f), std::vector<float>(n, 0.f)};
  float* out[2] = {ears[0].data(), ears[1].data()};
  for (size_t c = 0; c < filters_.size(); ++c)
    for (int e = 0; e < 2; ++e) {
      const std::vector<float>& f = filters_[c][size_t(e)];
      for (size_t i = 0; i < n; ++i) {
        const float x = channels[c][i];
        if (x == 0.f) continue;
        const size_t m = std::min(f.size(), n - i);
        for (size_t t = 0; t < m; ++t) out[e][i + t] += x * f[t];
      }
    }
  float* dest[2] = {left, right};
  for (int e = 0; e < 2; ++e)
    for (size_t i = 0; i < n; ++i) {
      const float x = ears[e][i];
      if (x == 0.f) continue;
      const size_t m = std::min(equaliser_.size(), n - i);
      for (size_t t = 0; t < m; ++t) dest[e][i + t] += x * equaliser_[t];
    }
}

}  // namespace dpc::audio
