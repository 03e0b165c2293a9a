#include "synthesis/noise_orthogonaliser.h"

#include <algorithm>
#include <cmath>

#include "common/fftw_util.h"
#include "common/octave_band_masks.h"

namespace dpc {

namespace {

/// The smallest transform: shorter deterministic parts are padded to it.
constexpr size_t kMinTransform = 4096;
/// A band whose image holds less than this share of the largest image's energy is left out of
/// the projection (nothing of the deterministic part there to be correlated with).
constexpr double kNegligibleImage = 1e-12;
/// The kernels' reach: where the lowest band's filter keeps this share of its impulse energy.
constexpr double kRingOut = 1e-6;
/// The deterministic part's extent: its samples above this fraction of its largest magnitude
/// (the placed pulses' band filters ring on far below it, down to -100 dB).
constexpr float kSignificant = 1e-4f;
/// Ridge on the Gram matrix's diagonal, relative: adjacent octave filters overlap, so their
/// images are close to but never exactly collinear.
constexpr double kRidge = 1e-9;

/// Samples until the unit impulse response of `f` keeps less than `share` of its energy.
size_t ringOut(const OctaveBandPass& f, int sampleRate, double share) {
  const size_t n = size_t(sampleRate);  // one second holds the 63 Hz band's ring-out
  std::vector<double> y(n);
  OctaveBandPass::State state{};
  for (size_t i = 0; i < n; ++i) y[i] = f.step(i == 0 ? 1.0 : 0.0, state);
  double tail = 0.0, total = 0.0;
  for (double v : y) total += v * v;
  for (size_t i = n; i-- > 0;) {
    tail += y[i] * y[i];
    if (tail > share * total) return i + 1;
  }
  return n;
}

/// Solves the symmetric positive definite system a x = r (a: n x n, row-major) in place by
/// Cholesky; false when a is not positive definite.
template <size_t N>
bool solveSpd(std::array<double, N * N>& a, std::array<double, N>& r, size_t n) {
  for (size_t j = 0; j < n; ++j) {
    double d = a[j * N + j];
    for (size_t k = 0; k < j; ++k) d -= a[j * N + k] * a[j * N + k];
    if (!(d > 0.0)) return false;
    a[j * N + j] = std::sqrt(d);
    for (size_t i = j + 1; i < n; ++i) {
      double s = a[i * N + j];
      for (size_t k = 0; k < j; ++k) s -= a[i * N + k] * a[j * N + k];
      a[i * N + j] = s / a[j * N + j];
    }
  }
  for (size_t i = 0; i < n; ++i) {  // L y = r
    for (size_t k = 0; k < i; ++k) r[i] -= a[i * N + k] * r[k];
    r[i] /= a[i * N + i];
  }
  for (size_t i = n; i-- > 0;) {  // L^T x = y
    for (size_t k = i + 1; k < n; ++k) r[i] -= a[k * N + i] * r[k];
    r[i] /= a[i * N + i];
  }
  return true;
}

}  // namespace

struct NoiseOrthogonaliser::Transform {
  Transform(size_t n, int sampleRate, const std::array<OctaveBandPass, kNumBands>& filters,
            int firstBand, int lastBand)
      : fft(n) {
    for (int b = firstBand; b <= lastBand; ++b) {
      power[size_t(b)].assign(n / 2 + 1, 0.f);
      if (!analysableBand(b, sampleRate)) continue;
      for (size_t k = 0; k <= n / 2; ++k)  // the inverse transform's 1/n folded in
        power[size_t(b)][k] = float(filters[size_t(b)].powerResponse(
                                        double(k) * sampleRate / double(n), sampleRate) /
                                    double(n));
    }
  }
  FftwRealTransforms fft;
  std::array<std::vector<float>, kNumBands> power;
};

NoiseOrthogonaliser::NoiseOrthogonaliser(int sampleRate, size_t length, int firstBand,
                                         int lastBand)
    : sampleRate_(sampleRate), length_(length), firstBand_(firstBand), lastBand_(lastBand) {
  for (int b = firstBand; b <= lastBand; ++b)
    if (analysableBand(b, sampleRate))
      filters_[size_t(b)] = OctaveBandPass::design(bandCentreExactHz(b), sampleRate);
  pad_ = ringOut(filters_[size_t(firstBand)], sampleRate, kRingOut);
}

NoiseOrthogonaliser::~NoiseOrthogonaliser() = default;

NoiseOrthogonaliser::Transform& NoiseOrthogonaliser::transformFor(size_t samples) {
  size_t n = kMinTransform;
  while (n < samples) n *= 2;
  for (auto& t : transforms_)
    if (t->fft.n == n) return *t;
  transforms_.push_back(
      std::make_unique<Transform>(n, sampleRate_, filters_, firstBand_, lastBand_));
  for (auto& u : u_)
    if (u.size() < n) u.assign(n, 0.0);
  return *transforms_.back();
}

void NoiseOrthogonaliser::bandImages(Transform& t, const float* fixed, size_t from,
                                     size_t span) {
  FftwRealTransforms& f = t.fft;
  std::fill(f.time.p, f.time.p + f.n, 0.f);
  std::copy(fixed + from, fixed + from + span, f.time.p);
  fftwf_execute(f.fwd);
  for (int b = firstBand_; b <= lastBand_; ++b) {
    const std::vector<float>& p = t.power[size_t(b)];
    for (size_t k = 0; k <= f.n / 2; ++k)
      for (int i = 0; i < 2; ++i) f.band.p[k][i] = f.spec.p[k][i] * p[k];
    fftwf_execute(f.inv);
    std::copy(f.time.p, f.time.p + span, u_[size_t(b)].begin());
  }
}

std::array<double, kNumBands> NoiseOrthogonaliser::coefficients(const float* noise,
                                                                size_t span) const {
  std::array<double, kNumBands * kNumBands> gram{};
  std::array<double, kNumBands> r{};
  const size_t lo = size_t(firstBand_), hi = size_t(lastBand_);
  for (size_t t = 0; t < span; ++t) {
    if (noise[t] == 0.f) continue;  // outside the noise's support
    for (size_t i = lo; i <= hi; ++i) {
      r[i] += double(noise[t]) * u_[i][t];
      for (size_t j = lo; j <= i; ++j) gram[i * kNumBands + j] += u_[i][t] * u_[j][t];
    }
  }
  double largest = 0.0;
  for (size_t i = 0; i < size_t(kNumBands); ++i) largest = std::max(largest, gram[i * kNumBands + i]);
  // The bands that take part, packed to the front.
  std::array<size_t, kNumBands> used{};
  size_t n = 0;
  for (size_t i = 0; i < size_t(kNumBands); ++i)
    if (gram[i * kNumBands + i] > kNegligibleImage * largest) used[n++] = i;
  std::array<double, kNumBands * kNumBands> a{};
  std::array<double, kNumBands> x{};
  for (size_t i = 0; i < n; ++i) {
    x[i] = r[used[i]];
    for (size_t j = 0; j <= i; ++j)
      a[i * kNumBands + j] = gram[used[i] * kNumBands + used[j]];
    a[i * kNumBands + i] *= 1.0 + kRidge;
  }
  std::array<double, kNumBands> beta{};
  if (n == 0 || !solveSpd<kNumBands>(a, x, n)) return beta;
  for (size_t i = 0; i < n; ++i) beta[used[i]] = x[i];
  return beta;
}

void NoiseOrthogonaliser::apply(float* noise, const float* fixed) {
  float peak = 0.f;
  for (size_t t = 0; t < length_; ++t) peak = std::max(peak, std::abs(fixed[t]));
  size_t first = length_, last = 0;
  for (size_t t = 0; t < length_; ++t)
    if (std::abs(fixed[t]) > kSignificant * peak) {
      first = std::min(first, t);
      last = t;
    }
  if (first == length_) return;
  const size_t from = first > pad_ ? first - pad_ : 0;
  const size_t to = std::min(length_, last + pad_ + 1);
  // Zero-phase kernels reach pad_ either side: a transform of span + pad_ holds them unwrapped.
  Transform& t = transformFor(to - from + pad_);
  bandImages(t, fixed, from, to - from);
  const std::array<double, kNumBands> beta = coefficients(noise + from, to - from);
  for (size_t i = 0; i < to - from; ++i) {
    if (noise[from + i] == 0.f) continue;
    double s = 0.0;
    for (int b = firstBand_; b <= lastBand_; ++b) s += beta[size_t(b)] * u_[size_t(b)][i];
    noise[from + i] = float(double(noise[from + i]) - s);
  }
}

}  // namespace dpc
