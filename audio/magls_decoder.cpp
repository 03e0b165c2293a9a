#include "audio/magls_decoder.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include "common/fftw_util.h"
#include "common/sphere_quadrature.h"
#include "common/spherical_harmonics.h"

namespace dpc::audio {

namespace {

using Complex = std::complex<double>;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Fibonacci lattice points behind the measurements' cell weights: a cell's weight is off by
/// about one lattice spacing (0.65 degrees) along its boundary, a few per cent for KEMAR's.
constexpr int kCellSamples = 100000;

/// Lattice points that find the region a set never measured (3.2 degrees apart).
constexpr int kGapSamples = 4000;

/// The fitted set on an fftSize-point grid: directions, quadrature weights and spectra
/// H_q,ear(f_k) (each HRIR's onset delay included as a phase), stored bin-major so that one
/// bin's Q values are contiguous. The first `measured` entries are the SOFA file's
/// measurements; the rest fill the region it never measured (see addGapDirections).
struct MeasuredSet {
  size_t count = 0, measured = 0, bins = 0, fftSize = 0;
  std::vector<std::array<double, 3>> directions;
  std::vector<double> weights;
  std::vector<std::complex<float>> spectra;  ///< [(k * 2 + ear) * count + q]
  const std::complex<float>* bin(size_t k, int ear) const {
    return spectra.data() + (k * 2 + size_t(ear)) * count;
  }
  std::complex<float>* bin(size_t k, int ear) {
    return spectra.data() + (k * 2 + size_t(ear)) * count;
  }
};

/// Directions of a kGapSamples-point Fibonacci lattice farther than `spacing` (radians of arc)
/// from every measured direction: the region the set never measured, each point standing for
/// an equal share of `area` (that region's fraction of the sphere).
void addGapDirections(MeasuredSet& s, double spacing, double area) {
  const double minDot = std::cos(spacing);
  std::vector<std::array<double, 3>> gap;
  for (int i = 0; i < kGapSamples; ++i) {
    const std::array<double, 3> p = fibonacciPoint(i, kGapSamples);
    bool near = false;
    for (size_t q = 0; q < s.measured && !near; ++q)
      near = p[0] * s.directions[q][0] + p[1] * s.directions[q][1] + p[2] * s.directions[q][2] >=
             minDot;
    if (!near) gap.push_back(p);
  }
  for (const auto& p : gap) {
    s.directions.push_back(p);
    s.weights.push_back(area / double(gap.size()));
  }
}

/// Directions and weights: the measurements' cells (cut at the set's coarsest spacing), then
/// the gap's points.
MeasuredSet directionsAndWeights(const Hrtf& hrtf) {
  MeasuredSet s;
  s.measured = hrtf.measurementCount();
  std::vector<float> l(size_t(hrtf.filterLength())), r(l.size());
  for (size_t q = 0; q < s.measured; ++q) {
    float u[3], dl, dr;
    hrtf.measurement(q, u, l.data(), r.data(), &dl, &dr);
    s.directions.push_back({u[0], u[1], u[2]});
  }
  const double spacing = coarsestSpacing(s.directions);
  s.weights = cellWeights(s.directions, spacing, kCellSamples);
  double covered = 0.0;
  for (double w : s.weights) covered += w;
  addGapDirections(s, spacing, std::max(0.0, 1.0 - covered));
  s.count = s.directions.size();
  return s;
}

/// The set's spectra: measurement q's HRIRs, or per-path binaural's grid lookup (Hrtf::hrir)
/// for the gap's directions.
MeasuredSet measuredSet(const Hrtf& hrtf, size_t fftSize) {
  MeasuredSet s = directionsAndWeights(hrtf);
  s.fftSize = fftSize;
  s.bins = fftSize / 2 + 1;
  s.spectra.resize(s.bins * 2 * s.count);
  FftwRealTransforms fft(fftSize);
  const size_t taps = size_t(hrtf.filterLength());
  std::vector<float> ears[2] = {std::vector<float>(taps), std::vector<float>(taps)};
  for (size_t q = 0; q < s.count; ++q) {
    float u[3] = {float(s.directions[q][0]), float(s.directions[q][1]), float(s.directions[q][2])};
    float delay[2];
    if (q < s.measured)
      hrtf.measurement(q, u, ears[0].data(), ears[1].data(), &delay[0], &delay[1]);
    else
      hrtf.hrir(u, ears[0].data(), ears[1].data(), &delay[0], &delay[1]);
    for (int e = 0; e < 2; ++e) {
      std::fill(fft.time.p, fft.time.p + fftSize, 0.f);
      std::copy(ears[e].begin(), ears[e].end(), fft.time.p);
      fftwf_execute(fft.fwd);
      for (size_t k = 0; k < s.bins; ++k) {
        const Complex x(fft.spec.p[k][0], fft.spec.p[k][1]);
        const double phase = -kTwoPi * double(k) * double(delay[e]) / double(fftSize);
        s.bin(k, e)[q] = std::complex<float>(delay[e] == 0.f ? x : x * std::polar(1.0, phase));
      }
    }
  }
  return s;
}

/// The set's bulk delay, samples: the mean phase step per bin of its weighted, both-ear
/// average response over bins [low, high) (a weighted circular mean, robust to the
/// response's notches), as a group delay.
double bulkDelay(const MeasuredSet& s, size_t low, size_t high) {
  const auto average = [&](size_t k) {
    Complex a = 0.0;
    for (int e = 0; e < 2; ++e)
      for (size_t q = 0; q < s.count; ++q) a += s.weights[q] * Complex(s.bin(k, e)[q]);
    return a;
  };
  Complex step = 0.0, previous = average(std::max<size_t>(low, 1) - 1);
  for (size_t k = std::max<size_t>(low, 1); k < high; ++k) {
    const Complex a = average(k);
    step += a * std::conj(previous);
    previous = a;
  }
  return -std::arg(step) * double(s.fftSize) / kTwoPi;
}

/// Multiplies every spectrum by exp(i 2 pi k tau / fftSize): advances it by tau samples.
void advance(MeasuredSet& s, double tau) {
  for (size_t k = 0; k < s.bins; ++k) {
    const std::complex<float> r(std::polar(1.0, kTwoPi * double(k) * tau / double(s.fftSize)));
    for (int e = 0; e < 2; ++e)
      for (size_t q = 0; q < s.count; ++q) s.bin(k, e)[q] *= r;
  }
}

/// The weighted, regularised least-squares fit as a matrix: y (Q x C, N3D harmonics of the
/// measured directions, row-major) and p = (Y^T W Y + lambda I)^-1 Y^T W (C x Q, row-major),
/// so that p t fits the targets t_q in the least-squares sense.
struct Projector {
  size_t channels = 0, count = 0;
  std::vector<double> y, p;
};

/// Cholesky factor L (lower, row-major) of the symmetric positive definite n x n matrix g.
std::vector<double> cholesky(const std::vector<double>& g, size_t n) {
  std::vector<double> l(n * n, 0.0);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j <= i; ++j) {
      double sum = g[i * n + j];
      for (size_t k = 0; k < j; ++k) sum -= l[i * n + k] * l[j * n + k];
      l[i * n + j] = i == j ? std::sqrt(std::max(sum, 1e-300)) : sum / l[j * n + j];
    }
  return l;
}

/// Solves L L^T x = b in place (L from cholesky).
void choleskySolve(const std::vector<double>& l, size_t n, std::vector<double>& b) {
  for (size_t i = 0; i < n; ++i) {
    for (size_t k = 0; k < i; ++k) b[i] -= l[i * n + k] * b[k];
    b[i] /= l[i * n + i];
  }
  for (size_t i = n; i-- > 0;) {
    for (size_t k = i + 1; k < n; ++k) b[i] -= l[k * n + i] * b[k];
    b[i] /= l[i * n + i];
  }
}

Projector projector(int order, const MeasuredSet& s, double lambda) {
  Projector pr;
  pr.channels = size_t(ambisonicChannels(order));
  pr.count = s.count;
  const size_t C = pr.channels, Q = s.count;
  pr.y.resize(Q * C);
  std::array<float, ambisonicChannels(kMaxAmbisonicOrder)> sn3d{};
  for (size_t q = 0; q < Q; ++q) {
    const float u[3] = {float(s.directions[q][0]), float(s.directions[q][1]),
                        float(s.directions[q][2])};
    sphericalHarmonicsSn3d(order, u, sn3d);
    for (int n = 0; n <= order; ++n)
      for (int c = n * n; c < (n + 1) * (n + 1); ++c)
        pr.y[q * C + size_t(c)] = std::sqrt(2.0 * n + 1.0) * sn3d[size_t(c)];  // N3D
  }
  std::vector<double> gram(C * C, 0.0);
  for (size_t q = 0; q < Q; ++q)
    for (size_t i = 0; i < C; ++i)
      for (size_t j = 0; j < C; ++j)
        gram[i * C + j] += s.weights[q] * pr.y[q * C + i] * pr.y[q * C + j];
  for (size_t i = 0; i < C; ++i) gram[i * C + i] += lambda;
  const std::vector<double> l = cholesky(gram, C);
  pr.p.resize(C * Q);
  std::vector<double> column(C);
  for (size_t q = 0; q < Q; ++q) {
    for (size_t c = 0; c < C; ++c) column[c] = s.weights[q] * pr.y[q * C + c];
    choleskySolve(l, C, column);
    for (size_t c = 0; c < C; ++c) pr.p[c * Q + q] = column[c];
  }
  return pr;
}

/// Directions whose power from f_c up is below this fraction of the mean weigh as if they had
/// it: a dead or band-limited measurement must not take over the fit.
constexpr double kLevelWeightFloor = 1e-3;

/// The least squares of the MagLS band for `ear`: each measurement's weight times
/// (E / E_q)^alpha (alpha > 0), E_q the ear's power at u_q over bins [cut, bins) (at least
/// kLevelWeightFloor E), E its weighted mean, rescaled so that the measurements keep their
/// share of the sphere against the filled gap (see the header). A set with no power above f_c:
/// s's own weights.
Projector levelWeightedProjector(int order, const MeasuredSet& s, size_t cut, int ear,
                                 double alpha) {
  std::vector<double> power(s.measured, 0.0);
  for (size_t k = cut; k < s.bins; ++k) {
    const std::complex<float>* h = s.bin(k, ear);
    for (size_t q = 0; q < s.measured; ++q) power[q] += std::norm(h[q]);
  }
  double mean = 0.0, total = 0.0;
  for (size_t q = 0; q < s.measured; ++q) {
    mean += s.weights[q] * power[q];
    total += s.weights[q];
  }
  mean = total > 0.0 ? mean / total : 0.0;
  if (!(mean > 0.0)) return projector(order, s, kMagLsRegularisation);
  MeasuredSet weighted;
  weighted.count = s.count;
  weighted.directions = s.directions;
  weighted.weights = s.weights;
  // The filled gap keeps its plain weights: its blended HRIRs lose high frequencies that the
  // head does not (their onsets differ), and weighting them up would fit that loss.
  double scaled = 0.0;
  for (size_t q = 0; q < s.measured; ++q) {
    weighted.weights[q] *= std::pow(mean / std::max(power[q], kLevelWeightFloor * mean), alpha);
    scaled += weighted.weights[q];
  }
  for (size_t q = 0; q < s.measured; ++q) weighted.weights[q] *= total / scaled;
  return projector(order, weighted, kMagLsRegularisation);
}

/// The decoder's coefficients, bin-major: [(k * 2 + ear) * C + c] (N3D).
using Coefficients = std::vector<Complex>;

/// Row q of Y times the coefficients h[0 .. C): the decoder's response at u_q.
Complex decodedAt(const Projector& pr, size_t q, const Complex* h) {
  Complex d = 0.0;
  for (size_t c = 0; c < pr.channels; ++c) d += pr.y[q * pr.channels + c] * h[c];
  return d;
}

/// h[0 .. C) = p t: the least-squares fit of the targets t[0 .. Q).
void project(const Projector& pr, const std::vector<Complex>& t, Complex* h) {
  for (size_t c = 0; c < pr.channels; ++c) {
    Complex sum = 0.0;
    const double* row = pr.p.data() + c * pr.count;
    for (size_t q = 0; q < pr.count; ++q) sum += row[q] * t[q];
    h[c] = sum;
  }
}

/// Least squares below bin `cut` (pr), MagLS from it on (*magnitude[ear]): the target's phase
/// is the previous bin's decoded response's, its magnitude the measured one.
Coefficients fit(const MeasuredSet& s, const Projector& pr, const Projector* const magnitude[2],
                 size_t cut) {
  const size_t C = pr.channels;
  Coefficients h(s.bins * 2 * C);
  std::vector<Complex> target(s.count);
  for (size_t k = 0; k < s.bins; ++k)
    for (int e = 0; e < 2; ++e) {
      const std::complex<float>* measured = s.bin(k, e);
      const Complex* below = k > 0 ? h.data() + ((k - 1) * 2 + size_t(e)) * C : nullptr;
      const bool leastSquares = k < cut || k == 0;
      for (size_t q = 0; q < s.count; ++q) {
        if (leastSquares) {
          target[q] = Complex(measured[q]);
          continue;
        }
        const Complex d = decodedAt(pr, q, below);
        const double m = std::sqrt(double(std::norm(measured[q]))), a = std::sqrt(std::norm(d));
        target[q] = a > 0.0 ? (m / a) * d : Complex(m);
      }
      project(leastSquares ? pr : *magnitude[e], target, h.data() + (k * 2 + size_t(e)) * C);
    }
  return h;
}

/// A 2 x 2 complex matrix, row-major.
struct Mat2 {
  Complex a, b, c, d;
  Mat2 operator*(const Mat2& o) const {
    return {a * o.a + b * o.c, a * o.b + b * o.d, c * o.a + d * o.c, c * o.b + d * o.d};
  }
  Mat2 adjoint() const { return {std::conj(a), std::conj(c), std::conj(b), std::conj(d)}; }
  Complex det() const { return a * d - b * c; }
  Mat2 inverse() const {
    const Complex k = 1.0 / det();
    return {d * k, -b * k, -c * k, a * k};
  }
};

/// The Hermitian square root of a Hermitian positive definite 2 x 2 matrix:
/// (B + sqrt(det B) I) / sqrt(tr B + 2 sqrt(det B)) (Cayley-Hamilton).
Mat2 hermitianSqrt(const Mat2& m) {
  const double s = std::sqrt(std::max(0.0, m.det().real()));
  const double t = std::sqrt(std::max(1e-300, m.a.real() + m.d.real() + 2.0 * s));
  return {(m.a + s) / t, m.b / t, m.c / t, (m.d + s) / t};
}

/// M with M^H rHat M = r, closest to the identity: R^^(-1/2) P R^(1/2), P the unitary polar
/// factor of A^H, A = R^(1/2) R^^(1/2) (Vilkamo et al. 2013). The identity when either matrix
/// is singular to within 1e-9 of its trace squared.
Mat2 covarianceMatch(const Mat2& r, const Mat2& rHat) {
  const auto singular = [](const Mat2& m) {
    const double tr = m.a.real() + m.d.real();
    return !(m.det().real() > 1e-9 * tr * tr);
  };
  if (singular(r) || singular(rHat)) return {1.0, 0.0, 0.0, 1.0};
  const Mat2 k = hermitianSqrt(r), kHat = hermitianSqrt(rHat);
  const Mat2 a = k * kHat;
  const Mat2 polar = a.adjoint() * hermitianSqrt(a * a.adjoint()).inverse();
  return kHat.inverse() * polar * k;
}

/// sum_q w_q x_q^H x_q over rows x_q = [left right].
Mat2 covariance(const std::vector<double>& w, const std::vector<Complex>& left,
                const std::vector<Complex>& right) {
  Mat2 r{0.0, 0.0, 0.0, 0.0};
  for (size_t q = 0; q < w.size(); ++q) {
    r.a += w[q] * std::norm(left[q]);
    r.b += w[q] * std::conj(left[q]) * right[q];
    r.d += w[q] * std::norm(right[q]);
  }
  r.c = std::conj(r.b);
  return r;
}

/// Zaunschirm et al.'s diffuse-field covariance constraint on bins [cut, bins), over the
/// measured directions (the gap's filled-in HRIRs are no measurement of the diffuse field).
void constrainCovariance(const MeasuredSet& s, const Projector& pr, size_t cut, Coefficients& h) {
  const size_t C = pr.channels, Q = s.measured;
  const std::vector<double> w(s.weights.begin(), s.weights.begin() + long(Q));
  std::vector<Complex> ears[2] = {std::vector<Complex>(Q), std::vector<Complex>(Q)},
                       decoded[2] = {std::vector<Complex>(Q), std::vector<Complex>(Q)};
  for (size_t k = std::max<size_t>(cut, 1); k < s.bins; ++k) {
    Complex* hk[2] = {h.data() + k * 2 * C, h.data() + (k * 2 + 1) * C};
    for (int e = 0; e < 2; ++e)
      for (size_t q = 0; q < Q; ++q) {
        ears[e][q] = Complex(s.bin(k, e)[q]);
        decoded[e][q] = decodedAt(pr, q, hk[e]);
      }
    const Mat2 m =
        covarianceMatch(covariance(w, ears[0], ears[1]), covariance(w, decoded[0], decoded[1]));
    for (size_t c = 0; c < C; ++c) {
      const Complex l = hk[0][c], r = hk[1][c];
      hk[0][c] = l * m.a + r * m.c;
      hk[1][c] = l * m.b + r * m.d;
    }
  }
}

/// The SN3D time-domain filters: N3D coefficients times sqrt(2n + 1), delayed by `delay` samples,
/// inverse-transformed, cut to `length` taps and faded out over the last kMagLsFadeFraction.
ChannelEarFilters timeDomain(int order, const Coefficients& h, size_t bins, size_t fftSize,
                             double delay, size_t length) {
  const size_t C = size_t(ambisonicChannels(order));
  FftwRealTransforms fft(fftSize);
  ChannelEarFilters out(C);
  const size_t fade = size_t(double(length) * kMagLsFadeFraction);
  for (int n = 0; n <= order; ++n)
    for (size_t c = size_t(n * n); c < size_t((n + 1) * (n + 1)); ++c)
      for (int e = 0; e < 2; ++e) {
        for (size_t k = 0; k < bins; ++k) {
          const Complex x = std::sqrt(2.0 * n + 1.0) * h[(k * 2 + size_t(e)) * C + c] *
                            std::polar(1.0, -kTwoPi * double(k) * delay / double(fftSize));
          fft.band.p[k][0] = float(x.real());
          fft.band.p[k][1] = k + 1 == bins ? 0.f : float(x.imag());
        }
        fftwf_execute(fft.inv);
        std::vector<float>& f = out[c][size_t(e)];
        f.resize(length);
        for (size_t t = 0; t < length; ++t) {
          const double w = t + fade < length ? 1.0
                                             : 0.5 + 0.5 * std::cos(std::numbers::pi *
                                                                    double(t + fade + 1 - length) /
                                                                    double(fade + 1));
          f[t] = float(w * fft.time.p[t] / double(fftSize));
        }
      }
  return out;
}

}  // namespace

double magLsCovarianceFromHz(int order, const MagLsOptions& options) {
  const double bandLimitHz =
      double(order) * kMagLsSpeedOfSound / (2.0 * std::numbers::pi * kMagLsHeadRadius);
  return std::min(options.cutoffHz, bandLimitHz);
}

ChannelEarFilters magLsFilters(int order, const Hrtf& hrtf, const MagLsOptions& options,
                               size_t length) {
  order = std::clamp(order, 1, kMaxAmbisonicOrder);
  if (hrtf.measurementCount() < size_t(ambisonicChannels(order)))
    throw std::invalid_argument("MagLS: the HRTF set has fewer measurements than channels");
  length = std::max(length, size_t(hrtf.filterLength()));
  const size_t fftSize = 2 * nextPow2(length);
  MeasuredSet s = measuredSet(hrtf, fftSize);
  const double binHz = double(hrtf.sampleRate()) / double(fftSize);
  const size_t cut = std::clamp<size_t>(size_t(std::lround(options.cutoffHz / binHz)), 2, s.bins);
  const double tau = bulkDelay(s, size_t(std::lround(kMagLsDelayBandHz[0] / binHz)),
                               size_t(std::lround(kMagLsDelayBandHz[1] / binHz)));
  advance(s, tau);
  const Projector pr = projector(order, s, kMagLsRegularisation);
  // The MagLS band's projectors per ear: level-weighted from order 2 up, else pr itself.
  Projector weighted[2];
  const Projector* magnitude[2] = {&pr, &pr};
  if (order >= 2 && options.levelWeightExponent > 0.0)
    for (int e = 0; e < 2; ++e) {
      weighted[e] = levelWeightedProjector(order, s, cut, e, options.levelWeightExponent);
      magnitude[e] = &weighted[e];
    }
  Coefficients h = fit(s, pr, magnitude, cut);
  if (order <= options.covarianceMaxOrder) {
    const double fromHz = magLsCovarianceFromHz(order, options);
    constrainCovariance(s, pr, std::max<size_t>(1, size_t(std::lround(fromHz / binHz))), h);
  }
  const double delay = tau + kMagLsPreDelaySeconds * hrtf.sampleRate();
  return timeDomain(order, h, s.bins, fftSize, delay, length);
}

}  // namespace dpc::audio
