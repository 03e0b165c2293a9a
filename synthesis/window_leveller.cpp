#include "synthesis/window_leveller.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "common/octave_band_masks.h"
#include "common/octave_filter.h"
#include "synthesis/band_filters.h"
#include "synthesis/band_tilt.h"

namespace dpc {

/// A band's view at a reduced rate: the view y_b = M_b * r holds nothing above the mask's
/// reach, so it is transformed on the first n/2 + 1 bins' lowest `support` only, at nr points
/// (nr/2 >= 2 x support: the gain's modulation of the view, (g - 1) y_b, stays below nr/2 but
/// for a tail at -40 dB and below that the mask then cuts again). Its samples lie at full-rate
/// times m x ratio, ratio = n / nr.
struct WindowLeveller::View {
  size_t support = 0;  ///< bins 0..support-1 of the full spectrum where M_b > 0
  double ratio = 1.0;  ///< full-rate samples per view sample
  std::unique_ptr<FftwRealTransforms> fft;
  std::vector<float> fixed;  ///< the fixed part's view (its first fft->n samples)
};

struct WindowLeveller::Size {
  size_t n = 0;     ///< FFT points
  size_t span = 0;  ///< the longest span this size levels (n less the masks' reach)
  std::unique_ptr<FftwRealTransforms> fft;
  std::array<std::vector<float>, kNumBands> mask;  ///< M_b on the FFT bins (levelled bands)
  std::array<View, kNumBands> view;                ///< the levelled bands' reduced views
  /// coupling[b][k][h]: the energy view b sees of white noise of unit density over band k's
  /// half h (0: below its centre, 1: above), relative to a unit impulse (k = b - 1 .. b + 1).
  std::array<std::array<std::array<double, 2>, kNumBands>, kNumBands> coupling{};
  /// sum_f M_k^2 P_kh: the half-bands' widths on the FFT bins, for the tilt's normalisation.
  std::array<std::array<double, 2>, kNumBands> halfWidth{};
};

WindowLeveller::View WindowLeveller::reducedView(const std::vector<float>& mask, size_t n) {
  View v;
  for (size_t f = 0; f < mask.size(); ++f)
    if (mask[f] > 0.f) v.support = f + 1;
  const size_t nr = std::min(n, smoothFftSize(4 * std::max<size_t>(v.support, 1)));
  v.ratio = double(n) / double(nr);
  v.fft = std::make_unique<FftwRealTransforms>(nr);
  v.fixed.resize(nr);
  return v;
}

WindowLeveller::~WindowLeveller() = default;

WindowLeveller::WindowLeveller(int sampleRate, size_t length, int firstBand, int lastBand)
    : sampleRate_(sampleRate),
      length_(length),
      firstBand_(firstBand),
      lastBand_(lastBand),
      current_(smoothFftSize(length + bandFilterTaps(std::max(sampleRate, 1))) / 2 + 1),
      correction_(smoothFftSize(length + bandFilterTaps(std::max(sampleRate, 1))) / 2 + 1) {
  if (sampleRate <= 0 || length == 0 || firstBand < 0 || lastBand >= kNumBands ||
      firstBand > lastBand)
    throw std::invalid_argument("WindowLeveller: rate, length and bands must be valid");
  const size_t taps = bandFilterTaps(sampleRate);
  prepareWindows();
  for (size_t span : {length / 8, length / 4, length / 2, length}) {
    if (span == 0) continue;
    auto s = std::make_unique<Size>();
    s->n = smoothFftSize(span + taps);
    s->span = s->n - taps;
    s->fft = std::make_unique<FftwRealTransforms>(s->n);
    const OctaveBandMasks masks(sampleRate, s->n);
    const size_t nbins = s->n / 2 + 1;
    // above[k][f]: powerAbove at bin f for band k's centre (each computed once: the loops below
    // read it for three bands and both halves).
    std::array<std::vector<double>, kNumBands> above;
    for (int b = std::max(0, firstBand - 1); b <= std::min(kNumBands - 1, lastBand + 1); ++b) {
      above[size_t(b)].resize(nbins);
      for (size_t f = 0; f < nbins; ++f)
        above[size_t(b)][f] = powerAbove(double(f) * sampleRate / s->n, bandCentreExactHz(b));
    }
    const auto halfShare = [&](int k, int h, size_t f) {
      const double p = above[size_t(k)][f];
      return h == 1 ? p : 1.0 - p;
    };
    for (int b = std::max(0, firstBand - 1); b <= std::min(kNumBands - 1, lastBand + 1); ++b)
      for (size_t f = 0; f < nbins; ++f)
        for (int h = 0; h < 2; ++h)
          s->halfWidth[size_t(b)][size_t(h)] +=
              double(masks.gain(b, f)) * masks.gain(b, f) * halfShare(b, h, f);
    for (int b = firstBand; b <= lastBand; ++b) {
      s->mask[size_t(b)].resize(nbins);
      for (size_t f = 0; f < nbins; ++f) s->mask[size_t(b)][f] = masks.gain(b, f);
      s->view[size_t(b)] = reducedView(s->mask[size_t(b)], s->n);
      for (int k = std::max(0, b - 1); k <= std::min(kNumBands - 1, b + 1); ++k)
        for (size_t f = 0; f < nbins; ++f) {
          const double w = (f == 0 || f == nbins - 1) ? 1.0 : 2.0;  // one-sided spectrum
          const double m2 = double(masks.gain(b, f)) * masks.gain(b, f) * double(masks.gain(k, f)) *
                            masks.gain(k, f) * w / double(s->n);
          for (int h = 0; h < 2; ++h)
            s->coupling[size_t(b)][size_t(k)][size_t(h)] += m2 * halfShare(k, h, f);
        }
    }
    sizes_.push_back(std::move(s));
  }
}

void WindowLeveller::prepareWindows() {
  double shortest = double(length_);
  for (int b = firstBand_; b <= lastBand_; ++b) {
    const double fc = bandCentreExactHz(b);
    // A band whose analysis filter does not fit below Nyquist: about one period, as the others.
    analysisDelay_[size_t(b)] =
        fc * std::numbers::sqrt2 < 0.5 * sampleRate_
            ? OctaveBandPass::design(fc, sampleRate_).energyCentroid(size_t(sampleRate_))
            : sampleRate_ / fc;
    shortest = std::min(shortest, windowLength(b));
  }
  // The windows of the shortest length over the IR, one more for the first, laid before the
  // first arrival, and a spare.
  factor_.resize(size_t(double(length_) / shortest) + 2);
  windowEnergy_.reserve(factor_.size());
  windowCross_.reserve(factor_.size());
}

double WindowLeveller::windowFactor(double e, double x, double target) {
  // g^2 e + 2 g x = target: the noise's own energy and its cross term with the fixed part
  // (zero in expectation) together make the target: the positive root, in the form without
  // cancellation for either sign of x (sqrt(target / e) when x = 0); a negative x raises it
  // less far than a positive one lowers it (its cancellation holds in this view only: see the
  // header).
  const double g0 = std::sqrt(target / e), root = std::sqrt(x * x + e * target);
  const double g = x >= 0.0 ? target / (root + x) : (root - x) / e;
  return std::clamp(std::clamp(g, g0 / kCrossLower, g0 * kCrossRaise), 1.0 / kMaxFactor,
                    kMaxFactor);
}

size_t WindowLeveller::sizeFor(size_t span) const {
  for (size_t i = 0; i < sizes_.size(); ++i)
    if (sizes_[i]->span >= span) return i;
  return sizes_.size() - 1;
}

size_t WindowLeveller::spanOf(const EnergyResponse& energy) const {
  double total = 0.0;
  for (size_t j = 0; j < energy.binCount(); ++j)
    for (int k = firstBand_; k <= lastBand_; ++k) total += std::max(0.f, energy.bins()[j][k]);
  double remaining = total;
  size_t j = 0;
  for (; j < energy.binCount() && remaining > kSpanEnergy * total; ++j)
    for (int k = firstBand_; k <= lastBand_; ++k) remaining -= std::max(0.f, energy.bins()[j][k]);
  return std::min(length_, size_t(std::ceil(double(j) * energy.binSeconds() * sampleRate_)));
}

void WindowLeveller::viewTargets(const EnergyResponse& energy, const Size& s) {
  const size_t nbins = energy.binCount();
  for (int b = firstBand_; b <= lastBand_; ++b) targetDensity_[size_t(b)].assign(nbins, 0.0);
  tilt_.reset(energy);
  for (int k = std::max(0, firstBand_ - 1); k <= std::min(kNumBands - 1, lastBand_ + 1); ++k) {
    const auto [wl, wh] = s.halfWidth[size_t(k)];
    for (size_t j = 0; j < nbins; ++j) {
      const double e = std::max(0.f, energy.bins()[j][k]);
      if (e == 0.0) continue;
      // The within-band tilt, normalised to keep the band's energy (as the exact-IR model does).
      const HalfBandDensity r = tilt_.at(k, (double(j) + 0.5) * energy.binSeconds());
      const double norm = (wl + wh) / (r.low * wl + r.high * wh);
      for (int b = std::max(firstBand_, k - 1); b <= std::min(lastBand_, k + 1); ++b) {
        const auto& c = s.coupling[size_t(b)][size_t(k)];
        targetDensity_[size_t(b)][j] += e * norm * (r.low * c[0] + r.high * c[1]);
      }
    }
  }
}

double WindowLeveller::windowLength(int b) const {
  const double w0 = std::max(kWindowPeriods * sampleRate_ / bandCentreExactHz(b),
                             kMinWindowSeconds * sampleRate_);
  const double split = kAlignedSeconds * sampleRate_;
  return split / std::max(1.0, std::round(split / w0));
}

void WindowLeveller::windowFactors(int b, const EnergyResponse& energy, const View& v,
                                   size_t origin, size_t span) {
  const double w = windowLength(b), start = windowOrigin(b, origin);
  const Windows win{start, w, std::max<size_t>(1, size_t((double(span) - start) / w)),
                    double(span)};
  // Whole windows only: the last takes the span's remainder. A short remainder as a window of
  // its own (a few samples of a 125 Hz view can sit at a zero crossing) would read next to no
  // energy and take the largest factor: a burst 12-26 dB above the response just after the
  // span (BRAS CR4; tests/synthesis/low_band_windows_test.cpp).
  windowEnergies(v, win, span);
  // The target's running sum at sample t: whole response bins before it, and a share of its bin.
  const double perBin = energy.binSeconds() * sampleRate_;
  const std::vector<double>& d = targetDensity_[size_t(b)];
  auto targetBefore = [&](double t, size_t& j, double& sum) {
    while (j < d.size() && double(j + 1) * perBin <= t) sum += d[j++];
    return j < d.size() ? sum + d[j] * (t - double(j) * perBin) / perBin : sum;
  };
  size_t j = 0;
  // What a window cannot hold (too few pulses for kMaxFactor, or a factor held by kCrossLower
  // or kCrossRaise) is carried on, as the band envelope carries an empty bin's energy to the
  // next pulse: otherwise the band loses it. kCarryShare of what is pending goes to each next
  // window, so one window's shortfall does not bend the decay where it lands (the last takes
  // the rest).
  double sum = 0.0, before = targetBefore(0.0, j, sum), pending = 0.0;
  for (size_t i = 0; i < win.count; ++i) {
    const double lo = win.origin + double(i) * win.length;
    const double hi = i + 1 == win.count ? double(span) : std::min(double(span), lo + win.length);
    const double e = windowEnergy_[i], x = windowCross_[i];
    const double carried = i + 1 == win.count ? pending : kCarryShare * pending;
    pending -= carried;
    const double after = targetBefore(hi, j, sum), target = after - before + carried;
    before = after;
    const double g = e > 0.0 && target > 0.0 ? windowFactor(e, x, target) : 1.0;
    factor_[i] = float(g);
    pending += std::max(0.0, target - (g * g * e + 2.0 * g * x));
  }
  scaleByFactors(v, win);
}

void WindowLeveller::windowEnergies(const View& v, const Windows& win, size_t span) {
  // Each view sample stands for `ratio` full-rate samples (Parseval for a band-limited view):
  // window i holds the view samples m with m x ratio in [origin + i w, origin + (i + 1) w), the
  // first also what precedes it, the last up to the span's end.
  windowEnergy_.assign(win.count, 0.0);
  windowCross_.assign(win.count, 0.0);
  const float* y = v.fft->time.p;
  const size_t last = std::min(v.fft->n, size_t(std::ceil(double(span) / v.ratio)));
  size_t m = 0;
  for (size_t i = 0; i < win.count; ++i) {
    const double end = win.origin + double(i + 1) * win.length;  // full-rate time
    const size_t to =
        i + 1 == win.count ? last : std::min(last, size_t(std::max(0.0, std::ceil(end / v.ratio))));
    double e = 0.0, x = 0.0;
    for (size_t k = m; k < to; ++k) e += double(y[k]) * double(y[k]);
    if (hasFixed_)
      for (size_t k = m; k < to; ++k) x += double(y[k]) * double(v.fixed[k]);
    windowEnergy_[i] = v.ratio * e;
    windowCross_[i] = v.ratio * x;
    m = std::max(m, to);
  }
}

void WindowLeveller::scaleByFactors(const View& v, const Windows& win) const {
  // y <- (g - 1) y with g = factor_[i] inside window i, blended linearly with the neighbour's
  // across kBlend of a window around each boundary (no step, which the band's mask would
  // smear anyway); factor_[0] before the first window; the last window's factor up to the
  // span's end, blended there into 1 (no correction). The view sample m lies at full-rate time
  // m x ratio, u = (m ratio - origin) / w windows on.
  float* y = v.fft->time.p;
  const double step = v.ratio / win.length, u0 = -win.origin / win.length;
  const double half = 0.5 * kBlend, end = (win.end - win.origin) / win.length;
  const size_t last = win.count - 1;
  for (size_t m = 0; m < v.fft->n; ++m) {
    const double u = u0 + double(m) * step;
    if (u >= end + half) {
      std::fill(y + m, y + v.fft->n, 0.f);
      return;
    }
    const double k = std::floor(u + half);  // the nearest boundary at or below u + half
    const double p = u - k;                 // in [-half, 1 - half)
    double g;
    if (u >= end - half)
      g = factor_[last] + (1.0 - factor_[last]) * (u - end + half) / kBlend;
    else if (u < half)
      g = factor_[0];
    else if (p < half && size_t(k) <= last)  // blending window k - 1 into window k
      g = factor_[size_t(k) - 1] +
          (double(factor_[size_t(k)]) - factor_[size_t(k) - 1]) * (p + half) / kBlend;
    else
      g = factor_[std::min(size_t(k), last)];
    y[m] *= float(g - 1.0);
  }
}

void WindowLeveller::viewOf(Size& s, int b, const fftwf_complex* spectrum) {
  const float scale = 1.f / float(s.n);
  const std::vector<float>& m = s.mask[size_t(b)];
  FftwRealTransforms& fft = *s.view[size_t(b)].fft;
  const size_t rbins = fft.n / 2 + 1, support = std::min(s.view[size_t(b)].support, rbins);
  for (size_t f = 0; f < support; ++f) {
    fft.band.p[f][0] = spectrum[f][0] * m[f] * scale;
    fft.band.p[f][1] = spectrum[f][1] * m[f] * scale;
  }
  float* const band = reinterpret_cast<float*>(fft.band.p);
  std::fill(band + 2 * support, band + 2 * rbins, 0.f);
  fftwf_execute(fft.inv);  // the view y_b = M_b * r at fft.n points
}

void WindowLeveller::addViewCorrection(Size& s, int b) {
  const std::vector<float>& m = s.mask[size_t(b)];
  const View& v = s.view[size_t(b)];
  FftwRealTransforms& fft = *v.fft;
  fftwf_execute(fft.fwd);  // the view's correction (g - 1) y_b
  const size_t support = std::min(v.support, fft.n / 2 + 1);
  const float gain = float(v.ratio);  // a transform of n / ratio points: back to n points'
  for (size_t f = 0; f < support; ++f)
    for (int c = 0; c < 2; ++c) {
      const float corr = fft.spec.p[f][c] * m[f] * gain;
      correction_.p[f][c] += corr;
      current_.p[f][c] += corr;
    }
}

void WindowLeveller::pass(const EnergyResponse& energy, Size& s, size_t origin, size_t span) {
  for (int b = firstBand_; b <= lastBand_; ++b) {
    viewOf(s, b, current_.p);
    windowFactors(b, energy, s.view[size_t(b)], origin, span);
    addViewCorrection(s, b);
  }
}

void WindowLeveller::loadSpectrum(Size& s, const float* ir) {
  FftwRealTransforms& fft = *s.fft;
  const size_t copied = std::min(length_, s.n);
  std::copy(ir, ir + copied, fft.time.p);
  std::fill(fft.time.p + copied, fft.time.p + s.n, 0.f);
  fftwf_execute(fft.fwd);
  for (size_t f = 0; f < s.n / 2 + 1; ++f)
    for (int c = 0; c < 2; ++c) {
      current_.p[f][c] = fft.spec.p[f][c];
      correction_.p[f][c] = 0.f;
    }
}

void WindowLeveller::applyCorrection(Size& s, size_t onset, float* ir) {
  FftwRealTransforms& fft = *s.fft;
  const float scale = 1.f / float(s.n);
  for (size_t f = 0; f < s.n / 2 + 1; ++f)
    for (int c = 0; c < 2; ++c) fft.band.p[f][c] = correction_.p[f][c] * scale;
  fftwf_execute(fft.inv);
  // The correction from the first arrival on; its part at negative times (wrapped to the end of
  // the FFT, beyond the masks' reach after the span) is dropped.
  const size_t end = std::min(length_, s.n - bandFilterTaps(sampleRate_) / 2);
  for (size_t t = onset; t < end; ++t) ir[t] += fft.time.p[t];
}

void WindowLeveller::loadFixed(Size& s, const float* fixed) {
  hasFixed_ = fixed != nullptr;
  if (!hasFixed_) return;
  FftwRealTransforms& fft = *s.fft;
  const size_t copied = std::min(length_, s.n);
  std::copy(fixed, fixed + copied, fft.time.p);
  std::fill(fft.time.p + copied, fft.time.p + s.n, 0.f);
  fftwf_execute(fft.fwd);
  for (int b = firstBand_; b <= lastBand_; ++b) {
    View& v = s.view[size_t(b)];
    viewOf(s, b, fft.spec.p);
    std::copy(v.fft->time.p, v.fft->time.p + v.fft->n, v.fixed.begin());
  }
}

void WindowLeveller::level(const EnergyResponse& energy, size_t onset, float* ir,
                           const float* fixed) {
  const size_t span = spanOf(energy);
  if (span <= onset || energy.binCount() == 0) return;
  Size& s = *sizes_[sizeFor(span)];
  viewTargets(energy, s);
  loadFixed(s, fixed);
  loadSpectrum(s, ir);
  for (int it = 0; it < kIterations; ++it)
    pass(energy, s, onset, std::min(span, s.span));
  applyCorrection(s, onset, ir);
}

}  // namespace dpc
