#include "analysis/expected_band_analysis.h"

#include <fftw3.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "common/octave_filter.h"
#include "synthesis/band_filters.h"
#include "synthesis/band_tilt.h"

using namespace dpc;

namespace {

constexpr int kFs = 48000;
constexpr size_t kBin = 48, kPre = 8192, kFft = 65536;
constexpr int kRealisations = 48;

/// Bands falling with a different decay each from 5 ms, over 0.6 s in 1 ms bins.
EnergyResponse makeEnergyResponse() {
  EnergyResponse er(0.6, 1e-3);
  for (size_t j = 5; j < er.binCount(); ++j)
    for (int b = 0; b < kNumBands; ++b)
      er.bins()[j][b] =
          float(2e-4 * std::pow(10.0, -6.0 * (double(j) + 0.5) * 1e-3 / (0.9 - 0.08 * double(b))));
  return er;
}

/// A direct sound at 3 ms with a spectrum sloping up.
DirectSound makeDirect() {
  DirectSound direct;
  direct.visible = true;
  direct.delaySeconds = 0.003f;
  for (int b = 0; b < kNumBands; ++b) direct.intensity[b] = float(2e-3 * (1.0 + 0.2 * b));
  return direct;
}

/// Half octave h's share (0 below, 1 above band k's centre) of the power at FFT bin f.
double share(int k, int h, size_t f) {
  const double p = powerAbove(double(f) * kFs / double(kFft), bandCentreExactHz(k));
  return h == 0 ? 1.0 - p : p;
}

using Tilt = std::array<std::array<std::vector<double>, 2>, kNumBands>;

/// The within-band tilt w_kh[j] per band k, half octave h and bin j, keeping the band's energy.
Tilt withinBandTilt(const EnergyResponse& er, const OctaveBandMasks& masks) {
  const size_t nspec = kFft / 2 + 1;
  Tilt tilt;
  for (int k = 0; k < kNumBands; ++k) {
    double width[2] = {0.0, 0.0};
    for (int h = 0; h < 2; ++h)
      for (size_t f = 0; f < nspec; ++f)
        width[h] += double(masks.gain(k, f)) * masks.gain(k, f) * share(k, h, f);
    for (int h = 0; h < 2; ++h) tilt[size_t(k)][size_t(h)].resize(er.binCount());
    for (size_t j = 0; j < er.binCount(); ++j) {
      const HalfBandDensity d = halfBandDensity(er, k, (double(j) + 0.5) * 1e-3);
      const double norm = (width[0] + width[1]) / (d.low * width[0] + d.high * width[1]);
      tilt[size_t(k)][0][j] = d.low * norm;
      tilt[size_t(k)][1][j] = d.high * norm;
    }
  }
  return tilt;
}

/// Per band and 1 ms bin, the analysis filters' energy averaged over kRealisations noise IRs.
std::array<std::vector<double>, kNumBands> meanOverNoiseIrs(const EnergyResponse& er,
                                                            const DirectSound& direct) {
  const OctaveBandMasks masks(kFs, kFft);
  const size_t nspec = kFft / 2 + 1;
  const Tilt tilt = withinBandTilt(er, masks);
  std::vector<float> time(kFft);
  std::vector<fftwf_complex> spec(nspec), sum(nspec);
  fftwf_plan fwd = fftwf_plan_dft_r2c_1d(int(kFft), time.data(), spec.data(), FFTW_ESTIMATE);
  fftwf_plan inv = fftwf_plan_dft_c2r_1d(int(kFft), sum.data(), time.data(), FFTW_ESTIMATE);
  const size_t n = er.binCount() * kBin;
  const size_t directAt = kPre + 144;  // 3 ms
  std::array<std::vector<double>, kNumBands> mean;
  for (auto& m : mean) m.assign(er.binCount(), 0.0);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  for (int r = 0; r < kRealisations; ++r) {
    for (auto& s : sum) s[0] = s[1] = 0.f;
    for (int kh = 0; kh < 2 * kNumBands; ++kh) {
      const int k = kh / 2, h = kh % 2;
      std::fill(time.begin(), time.end(), 0.f);
      for (size_t i = 0; i < n; ++i)
        time[kPre + i] =
            float(normal(rng) * std::sqrt(er.bins()[i / kBin][k] *
                                          tilt[size_t(k)][size_t(h)][i / kBin] / double(kBin)));
      fftwf_execute(fwd);
      for (size_t f = 0; f < nspec; ++f) {
        const double g = std::sqrt(share(k, h, f)) * masks.gain(k, f) / double(kFft);
        // The direct pulse's share of band k: amplitude sqrt(M_k^2 E_k) would not
        // add up across bands, so the pulse is built once below from its power spectrum.
        sum[f][0] += float(spec[f][0] * g);
        sum[f][1] += float(spec[f][1] * g);
      }
    }
    for (size_t f = 0; f < nspec; ++f) {
      double p = 0.0;
      for (int k = 0; k < kNumBands; ++k)
        p += double(masks.gain(k, f)) * masks.gain(k, f) * direct.intensity[k];
      const double phase = -2.0 * 3.14159265358979323846 * double(f) * double(directAt) / kFft;
      sum[f][0] += float(std::sqrt(p) * std::cos(phase) / double(kFft));
      sum[f][1] += float(std::sqrt(p) * std::sin(phase) / double(kFft));
    }
    fftwf_execute(inv);
    for (int b = 0; b < kNumBands; ++b) {
      const OctaveBandPass filter = OctaveBandPass::design(bandCentreExactHz(b), kFs);
      const double unit = filter.impulseEnergy(size_t(kFs));  // the model's scale
      OctaveBandPass::State st{};
      for (size_t i = 0; i < kPre + n; ++i) {
        const double y = filter.step(time[i], st);
        if (i >= kPre + 3 * kBin)
          mean[size_t(b)][(i - kPre) / kBin] += y * y / (kRealisations * unit);
      }
    }
  }
  fftwf_destroy_plan(fwd);
  fftwf_destroy_plan(inv);
  return mean;
}

}  // namespace

TEST_CASE("As measured: the expected band analysis equals the mean over noise IRs of the model",
          "[analysis]") {
  // The model of expectedBandAnalysisEnergy built sample by sample: per band k and half
  // octave h (power split at fc by powerAbove), Gaussian white noise with per-sample energy
  // E_k[j] w_kh[j] / 48 (a band value is a spectral density), shaped in the frequency domain
  // by M_k sqrt(share_h); w_kh the within-band tilt (halfBandDensity, normalised to keep the band's
  // energy); plus the zero-phase direct pulse; through the analysis filters; squared and
  // binned; averaged over R realisations. Different decays per band (so the filters' skirts
  // and the tilt matter) and a direct sound with a sloping spectrum.
  const EnergyResponse er = makeEnergyResponse();
  const DirectSound direct = makeDirect();
  const auto model = expectedBandAnalysisEnergy(er, direct, kFs);
  const auto mean = meanOverNoiseIrs(er, direct);

  for (int b = 0; b < kNumBands; ++b) {
    const auto& want = model[size_t(b)];
    const auto& got = mean[size_t(b)];
    CHECK(want[0] == 0.0);  // before the onset (the direct sound's bin, 3)
    CHECK(want[2] == 0.0);
    // Energy in [3, 5) ms (mostly the direct sound), [5, 83), [83, 300) and [300, 600) ms.
    // Monte Carlo error: noise in a band B Hz wide (B = fc / sqrt 2, the octave) holds about
    // 2 B independent Gaussian samples per second; under a decaying envelope a window counts as
    // T_eff = (sum e)^2 / sum e^2 x 1 ms of it (e the model's energy per bin; the deterministic
    // direct pulse counted as noise, which overstates the error), so the mean energy of R
    // realisations has a relative standard deviation 1 / sqrt(B T_eff R). Allowed: 5 of those
    // (32 windows are compared, and the count of independent samples is approximate).
    const double bandwidth = bandCentreExactHz(b) / std::sqrt(2.0);
    const std::array<std::pair<size_t, size_t>, 4> windows = {
        {{3, 5}, {5, 83}, {83, 300}, {300, 600}}};
    for (const auto& [lo, hi] : windows) {
      double w = 0.0, w2 = 0.0, g = 0.0;
      for (size_t j = lo; j < hi; ++j) {
        w += want[j];
        w2 += want[j] * want[j];
        g += got[j];
      }
      const double tEff = w * w / w2 * 1e-3;
      const double sd = 1.0 / std::sqrt(bandwidth * tEff * kRealisations);
      INFO("band " << kBandCentreHz[size_t(b)] << " Hz, window " << lo << ".." << hi
                   << " ms: model " << w << ", mean of realisations " << g << ", sd " << sd);
      CHECK(std::abs(g / w - 1.0) < 5.0 * sd);
    }
  }
}
