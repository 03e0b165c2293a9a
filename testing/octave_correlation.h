// The test's own instrument for correlations between two signals per octave band: an ideal
// band-pass in the frequency domain (FFTW, single precision), independent of dpc's filters.
// Shared by the spatial tests (late-field independence, interaural coherence).
#pragma once

#include <fftw3.h>

#include <cmath>
#include <complex>
#include <vector>

namespace dpc::test {

struct Correlation {
  double value = 0.0;
  double sigma = 0.0;  ///< its sampling standard deviation for independent noises
};

using Spectrum = std::vector<std::complex<double>>;

/// Spectrum of x[begin, end).
inline Spectrum spectrum(const std::vector<float>& x, size_t begin, size_t end) {
  const int n = int(end - begin);
  std::vector<float> in(x.begin() + long(begin), x.begin() + long(end));
  std::vector<std::complex<float>> out(size_t(n / 2 + 1));
  fftwf_plan p = fftwf_plan_dft_r2c_1d(n, in.data(), reinterpret_cast<fftwf_complex*>(out.data()),
                                       FFTW_ESTIMATE);
  fftwf_execute(p);
  fftwf_destroy_plan(p);
  return Spectrum(out.begin(), out.end());
}

/// The band signal of spectrum x (n samples) on the bins where keep[k], squared and summed
/// over windows of `window` samples.
inline std::vector<double> windowEnergies(const Spectrum& x, const std::vector<bool>& keep, int n,
                                   size_t window) {
  std::vector<std::complex<float>> band(x.size());
  for (size_t k = 0; k < x.size(); ++k)
    band[k] = keep[k] ? std::complex<float>(x[k]) : std::complex<float>();
  std::vector<float> y(size_t(n), 0.f);
  fftwf_plan p = fftwf_plan_dft_c2r_1d(n, reinterpret_cast<fftwf_complex*>(band.data()), y.data(),
                                       FFTW_ESTIMATE);
  fftwf_execute(p);
  fftwf_destroy_plan(p);
  std::vector<double> e((y.size() + window - 1) / window, 0.0);
  for (size_t i = 0; i < y.size(); ++i) e[i / window] += double(y[i]) * y[i];
  return e;
}

/// Zero-lag normalised correlation of the signals of spectra u and v (n samples at rate) in
/// the octave around centreHz, and its sampling deviation: for independent noises of
/// bandwidth B whose energies per window w of T_w seconds are E_u,w and E_v,w,
/// var = sum_w E_u,w E_v,w / (B T_w sum_w E_u,w sum_w E_v,w) (1 / (B T) when stationary).
inline Correlation octaveCorrelation(const Spectrum& u, const Spectrum& v, int n, int rate,
                              double centreHz) {
  const double binHz = double(rate) / n, lo = centreHz / std::sqrt(2.0), hi = 2.0 * lo;
  std::vector<bool> keep(u.size());
  double cross = 0.0, eu = 0.0, ev = 0.0;
  for (size_t k = 0; k < u.size(); ++k) {
    keep[k] = double(k) * binHz >= lo && double(k) * binHz < hi;
    if (!keep[k]) continue;
    cross += (u[k] * std::conj(v[k])).real();
    eu += std::norm(u[k]);
    ev += std::norm(v[k]);
  }
  const size_t window = size_t(rate / 100);  // 10 ms: the late part's envelope is slower
  const std::vector<double> wu = windowEnergies(u, keep, n, window);
  const std::vector<double> wv = windowEnergies(v, keep, n, window);
  double sumU = 0.0, sumV = 0.0, sumUV = 0.0;
  for (size_t w = 0; w < wu.size(); ++w) {
    sumU += wu[w];
    sumV += wv[w];
    sumUV += wu[w] * wv[w];
  }
  const double var = sumUV / ((hi - lo) * double(window) / rate * sumU * sumV);
  return {cross / std::sqrt(eu * ev), std::sqrt(var)};
}

}  // namespace dpc::test
