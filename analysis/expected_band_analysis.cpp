#include "analysis/expected_band_analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "common/fftw_util.h"
#include "analysis/room_parameters.h"
#include "common/octave_filter.h"
#include "synthesis/band_filters.h"
#include "synthesis/band_tilt.h"

namespace dpc {

namespace {

using HalfBands = std::array<std::array<std::vector<double>, 2>, kNumBands>;

/// The model IR's parts shared by every analysed band.
struct Model {
  double fs = 0.0;
  double w = 0.0;                           ///< samples per response bin
  size_t half = 0;                          ///< the zero-phase impulses span time -half..half-1
  size_t nbins = 0;                         ///< response bins
  HalfBands mask;                           ///< m_kh's impulse responses, time -half at index 0
  HalfBands weight;                         ///< t_kh per response bin
  bool direct = false;                      ///< whether the direct sound is visible
  std::vector<double> pulse;                ///< the direct sound's impulse
  long directSample = -1;
  size_t onset = 0;  ///< the first response bin the band analysis counts
};

/// The zero-phase impulse response with the real amplitude spectrum amplitudeAt(f) on fft's
/// bins, time -half..half-1 at index 0..2 half-1.
template <typename Amplitude>
std::vector<double> zeroPhaseImpulse(FftwRealTransforms& fft, size_t half, Amplitude amplitudeAt) {
  const size_t nfft = fft.n;
  for (size_t f = 0; f < nfft / 2 + 1; ++f) {
    fft.band.p[f][0] = float(amplitudeAt(f) / double(nfft));
    fft.band.p[f][1] = 0.f;
  }
  fftwf_execute(fft.inv);
  std::vector<double> h(2 * half);
  for (size_t i = 0; i < h.size(); ++i) h[i] = fft.time.p[(i + nfft - half) % nfft];
  return h;
}

/// Each band's noise in two half-octave processes (power split at fc by powerAbove), whose
/// energies follow the within-band tilt (halfBandDensity) per response bin.
void halfBandProcesses(const EnergyResponse& energy, const OctaveBandMasks& masks,
                       FftwRealTransforms& fft, Model& m) {
  const size_t nfft = fft.n;
  std::array<std::array<double, 2>, kNumBands> halfWidth{};
  for (int k = 0; k < kNumBands; ++k)
    for (int h = 0; h < 2; ++h) {
      const double fc = bandCentreExactHz(k);
      auto share = [&](size_t f) {
        const double p = powerAbove(m.fs * double(f) / double(nfft), fc);
        return h == 0 ? 1.0 - p : p;
      };
      m.mask[size_t(k)][size_t(h)] = zeroPhaseImpulse(
          fft, m.half, [&](size_t f) { return double(masks.gain(k, f)) * std::sqrt(share(f)); });
      for (size_t f = 0; f < nfft / 2 + 1; ++f)
        halfWidth[size_t(k)][size_t(h)] += double(masks.gain(k, f)) * masks.gain(k, f) * share(f);
    }
  for (int k = 0; k < kNumBands; ++k) {
    const auto [wl, wh] = halfWidth[size_t(k)];
    for (auto& v : m.weight[size_t(k)]) v.assign(m.nbins, 1.0);
    for (size_t j = 0; j < m.nbins; ++j) {
      const HalfBandDensity r = halfBandDensity(energy, k, (double(j) + 0.5) * energy.binSeconds());
      const double norm = (wl + wh) / (r.low * wl + r.high * wh);
      m.weight[size_t(k)][0][j] = r.low * norm;
      m.weight[size_t(k)][1][j] = r.high * norm;
    }
  }
}

/// The broadband onset: the band analysis integrates from the direct sound (or the first
/// arrival), so nothing before its bin counts.
size_t analysisOnset(const EnergyResponse& energy, const DirectSound& direct, const Model& m) {
  size_t onset = m.nbins;
  if (direct.visible) onset = std::min(m.nbins, size_t(std::floor(double(m.directSample) / m.w)));
  for (size_t j = 0; j < std::min(onset, m.nbins); ++j)
    for (int k = 0; k < kNumBands; ++k)
      if (energy.bins()[j][k] > 0.f) {
        onset = j;
        break;
      }
  return onset;
}

Model buildModel(const EnergyResponse& energy, const DirectSound& direct, int sampleRate) {
  Model m;
  m.fs = double(sampleRate);
  m.w = energy.binSeconds() * m.fs;
  m.nbins = energy.binCount();
  // The masks' crossovers span 1/3 octave, >= 20 Hz: negligible beyond 1/4 s.
  m.half = size_t(sampleRate / 4);
  FftwRealTransforms fft(nextPow2(2 * m.half));
  const OctaveBandMasks masks(sampleRate, fft.n);
  halfBandProcesses(energy, masks, fft, m);
  if (direct.visible)
    m.pulse = zeroPhaseImpulse(fft, m.half, [&](size_t f) {
      double s = 0.0;
      for (int k = 0; k < kNumBands; ++k) {
        const double g = masks.gain(k, f);
        s += g * g * std::max(0.0, double(direct.intensity[k]));
      }
      return std::sqrt(s);
    });
  m.direct = direct.visible;
  m.directSample = direct.visible ? std::lround(double(direct.delaySeconds) * m.fs) : -1;
  m.onset = analysisOnset(energy, direct, m);
  return m;
}

/// One analysed band's convolution of the model with its analysis filter, at the response's
/// bin resolution. The filter's response rings on after the mask's span; 1/2 s takes the
/// 63 Hz octave's 6th-order Butterworth more than 100 dB down.
class BandAnalysis {
 public:
  BandAnalysis(const Model& m, int sampleRate)
      : m_(m),
        ring_(size_t(sampleRate / 2)),
        span_(2 * m.half + ring_),
        wi_(std::max<size_t>(1, size_t(std::lround(m.w)))),
        // Bin offsets d = i - j at which a unit bin j feeds output bin i: from the kernel's
        // first sample (-half) to its last, one bin either side for the bin averaging.
        dMin_(-long(m.half / wi_) - 2),
        dMax_(long((m.half + ring_) / wi_) + 2),
        prefix_(span_ + 1),
        cumulative_(size_t(dMax_ - dMin_ + 2)),
        g_(size_t(dMax_ - dMin_ + 1)),
        u_(span_) {}

  /// out (nbins) = the expected analysed energy of band b.
  void run(const EnergyResponse& energy, int b, std::vector<double>& out) {
    filter_ = OctaveBandPass::design(bandCentreExactHz(b), m_.fs);
    out.assign(m_.nbins, 0.0);
    for (int kh = 0; kh < 2 * kNumBands; ++kh) {
      const int k = kh / 2, part = kh % 2;
      filtered(m_.mask[size_t(k)][size_t(part)]);
      binKernel();
      spread(energy, k, m_.weight[size_t(k)][size_t(part)], out);
    }
    if (m_.direct) addDirect(out);
  }

 private:
  /// u = x through the analysis filter, span_ samples.
  void filtered(const std::vector<double>& x) {
    OctaveBandPass::State st{};
    for (size_t n = 0; n < span_; ++n) {
      u_[n] = filter_.step(n < x.size() ? x[n] : 0.0, st);
      if (n % 64 == 63) OctaveBandPass::flushTiny(st);
    }
  }
  /// g_[d - dMin]: the part of a unit energy spread evenly over a bin j's wi samples that
  /// lands in output bin j + d, for the kernel K = (h_b * m_k)^2 = u^2.
  void binKernel() {
    prefix_[0] = 0.0;  // prefix[s]: kernel energy at times < s - half
    for (size_t n = 0; n < span_; ++n) prefix_[n + 1] = prefix_[n] + u_[n] * u_[n];
    auto below = [&](long t) {  // kernel energy at times < t (t in samples)
      const long s = t + long(m_.half);
      return prefix_[size_t(std::clamp<long>(s, 0, long(span_)))];
    };
    // cumulative[d - dMin]: output energy before the start of output bin j + d.
    for (long d = dMin_; d <= dMax_ + 1; ++d) {
      double c = 0.0;
      for (size_t m = 0; m < wi_; ++m) c += below(d * long(wi_) - long(m));
      cumulative_[size_t(d - dMin_)] = c / double(wi_);
    }
    for (long d = dMin_; d <= dMax_; ++d)
      g_[size_t(d - dMin_)] = cumulative_[size_t(d + 1 - dMin_)] - cumulative_[size_t(d - dMin_)];
  }
  /// out += every response bin's energy of band k (tilted) through the bin kernel.
  void spread(const EnergyResponse& energy, int k, const std::vector<double>& tilt,
              std::vector<double>& out) const {
    for (size_t j = 0; j < m_.nbins; ++j) {
      const double e = energy.bins()[j][k] * tilt[j];
      if (!(e > 0.0)) continue;
      const long iLo = std::max<long>(long(m_.onset), long(j) + dMin_);
      const long iHi = std::min<long>(long(m_.nbins) - 1, long(j) + dMax_);
      for (long i = iLo; i <= iHi; ++i) out[size_t(i)] += e * g_[size_t(i - long(j) - dMin_)];
    }
  }
  /// out += the direct pulse through the analysis filter, squared, per bin.
  void addDirect(std::vector<double>& out) {
    filtered(m_.pulse);
    for (size_t n = 0; n < span_; ++n) {
      const long s = m_.directSample + long(n) - long(m_.half);
      if (s < 0) continue;
      const size_t i = size_t(std::floor(double(s) / m_.w));
      if (i >= m_.nbins) break;
      if (i >= m_.onset) out[i] += u_[n] * u_[n];
    }
  }

  const Model& m_;
  size_t ring_, span_, wi_;
  long dMin_, dMax_;
  OctaveBandPass filter_{};
  std::vector<double> prefix_, cumulative_, g_, u_;
};

}  // namespace

std::array<std::vector<double>, kNumBands> expectedBandAnalysisEnergy(const EnergyResponse& energy,
                                                                      const DirectSound& direct,
                                                                      int sampleRate) {
  const double w = energy.binSeconds() * double(sampleRate);  // samples per response bin
  if (sampleRate <= 0 || !(w >= 1.0))
    throw std::invalid_argument("expectedBandAnalysisEnergy: rate <= 0 or bins below a sample");
  const Model model = buildModel(energy, direct, sampleRate);
  BandAnalysis analysis(model, sampleRate);
  std::array<std::vector<double>, kNumBands> out;
  for (int b = 0; b < kNumBands; ++b) {
    if (!analysableBand(b, model.fs))
      out[size_t(b)].assign(model.nbins, std::numeric_limits<double>::quiet_NaN());
    else {
      analysis.run(energy, b, out[size_t(b)]);
      // On the band analysis's scale (room_parameters.h: divided by the filter's unit-impulse
      // energy).
      const double unit = audio::analysisFilterImpulseEnergy(b, model.fs);
      for (double& e : out[size_t(b)]) e /= unit;
    }
  }
  return out;
}

}  // namespace dpc
