#include "analysis/ambisonic_diffuseness.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "common/octave_filter.h"

namespace dpc::audio {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kOnsetBelowPeakDb = 20.0;

using Channels = std::vector<std::vector<double>>;

/// W's first sample within kOnsetBelowPeakDb of its squared peak; w.size() when silent.
size_t onsetOf(const std::vector<double>& w) {
  double peak = 0.0;
  for (double x : w) peak = std::max(peak, x * x);
  if (!(peak > 0.0) || !std::isfinite(peak)) return w.size();
  const double threshold = peak * std::pow(10.0, -kOnsetBelowPeakDb / 10.0);
  size_t i = 0;
  while (w[i] * w[i] < threshold) ++i;
  return i;
}

/// DirAC's diffuseness of the first-order channels over [begin, end).
double dirac(const Channels& a, size_t begin, size_t end) {
  double ix = 0.0, iy = 0.0, iz = 0.0, e = 0.0;
  for (size_t t = begin; t < end; ++t) {
    const double w = a[0][t], x = a[3][t], y = a[1][t], z = a[2][t];
    ix += w * x, iy += w * y, iz += w * z;
    e += 0.5 * (w * w + x * x + y * y + z * z);
  }
  if (!(e > 0.0)) return kNaN;
  return std::clamp(1.0 - std::sqrt(ix * ix + iy * iy + iz * iz) / e, 0.0, 1.0);
}

/// COMEDIE's diffuseness of every channel over [begin, end) (SN3D in, N3D covariance).
double comedie(const Channels& a, size_t begin, size_t end) {
  const int m = int(a.size());
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(m, m);
  std::vector<double> scale(static_cast<size_t>(m));
  for (int k = 0; k < m; ++k) scale[size_t(k)] = std::sqrt(2.0 * std::floor(std::sqrt(double(k))) + 1.0);
  for (int i = 0; i < m; ++i)
    for (int j = i; j < m; ++j) {
      double s = 0.0;
      for (size_t t = begin; t < end; ++t) s += a[size_t(i)][t] * a[size_t(j)][t];
      c(i, j) = c(j, i) = s * scale[size_t(i)] * scale[size_t(j)];
    }
  const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(c).eigenvalues();
  const double mean = lambda.mean();
  if (!(mean > 0.0)) return kNaN;
  const double spread = (lambda.array() - mean).abs().sum();
  return std::clamp(1.0 - spread / (2.0 * (m - 1) * mean), 0.0, 1.0);
}

Channels octaveBand(const Channels& a, int b, double fs) {
  Channels out(a.size(), std::vector<double>(a[0].size()));
  const OctaveBandPass filter = OctaveBandPass::design(bandCentreExactHz(b), fs);
  for (size_t c = 0; c < a.size(); ++c) {
    OctaveBandPass::State state{};
    filter.run(a[c].data(), out[c].data(), a[c].size(), state);
  }
  return out;
}

}  // namespace

AmbisonicDiffuseness analyzeAmbisonicDiffuseness(std::span<const float* const> channels,
                                                 int order, size_t n, int sampleRate) {
  AmbisonicDiffuseness out;
  out.dirac.fill(kNaN);
  out.comedie.fill(kNaN);
  out.broadbandDirac = out.broadbandComedie = out.onsetSeconds = kNaN;
  const size_t m = size_t((order + 1) * (order + 1));
  if (order < 1 || channels.size() != m || n == 0 || sampleRate <= 0) return out;
  Channels a(m);
  for (size_t c = 0; c < m; ++c) a[c].assign(channels[c], channels[c] + n);
  const size_t onset = onsetOf(a[0]);
  if (onset == n) return out;
  const double fs = double(sampleRate);
  out.onsetSeconds = double(onset) / fs;
  const size_t begin = std::min(n, onset + size_t(std::lround(kDiffusenessLateSeconds * fs)));
  out.broadbandDirac = dirac(a, begin, n);
  out.broadbandComedie = comedie(a, begin, n);
  for (int b = 0; b < kNumBands; ++b) {
    if (bandCentreExactHz(b) * std::numbers::sqrt2 >= fs / 2) continue;
    const Channels band = octaveBand(a, b, fs);
    out.dirac[size_t(b)] = dirac(band, begin, n);
    out.comedie[size_t(b)] = comedie(band, begin, n);
  }
  return out;
}

}  // namespace dpc::audio
