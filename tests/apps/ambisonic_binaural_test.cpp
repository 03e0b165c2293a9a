// Binaural decoders of AmbiX (audio/ambisonic_binaural.h: MagLS, audio/magls_decoder.h, and
// the sampling decoder) against the HRTF they are made from, plane wave by plane wave: the
// interaural level difference per octave band, the interaural coherence of an isotropic
// diffuse field, and the level where the SOFA set has no measurement.
#include "audio/ambisonic_binaural.h"

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <functional>
#include <iomanip>
#include <sstream>
#include <vector>

#include "audio/hrtf.h"
#include "common/fftw_util.h"
#include "common/sphere_quadrature.h"
#include "common/spherical_harmonics.h"
#include "runtime/propagation_stage.h"
#include "testing/test_util.h"

using namespace dpc;
using audio::AmbisonicBinauralDecoder;
using audio::BinauralDecoderMethod;

namespace {

constexpr int kFs = 48000;
constexpr int kFirstBand = 2;  ///< 250 Hz

using Ears = std::array<std::vector<float>, 2>;

std::array<float, 3> unit(double azimuthDeg, double elevationDeg) {
  const double a = azimuthDeg * M_PI / 180, e = elevationDeg * M_PI / 180;
  return {float(std::cos(e) * std::cos(a)), float(std::cos(e) * std::sin(a)), float(std::sin(e))};
}

/// The decoder's ears (channel filters only; the equaliser is common to both ears) for a plane
/// wave from `dir`: sum_c Y_c(dir) F_c,ear.
Ears planeWave(const AmbisonicBinauralDecoder& d, int order, const std::array<float, 3>& dir) {
  std::array<float, ambisonicChannels(kMaxAmbisonicOrder)> y{};
  sphericalHarmonicsSn3d(order, dir.data(), y);
  const size_t n = d.filterLength();
  Ears ears{std::vector<float>(n, 0.f), std::vector<float>(n, 0.f)};
  for (size_t c = 0; c < size_t(ambisonicChannels(order)); ++c)
    for (int e = 0; e < 2; ++e)
      for (size_t t = 0; t < n; ++t) ears[size_t(e)][t] += y[c] * d.filter(c, e)[t];
  return ears;
}

/// The HRIR pair per-path binaural takes for `dir` (KEMAR's onset delays are zero).
Ears hrir(const audio::Hrtf& h, const std::array<float, 3>& dir) {
  const size_t n = size_t(h.filterLength());
  Ears ears{std::vector<float>(n, 0.f), std::vector<float>(n, 0.f)};
  float dl = 0, dr = 0;
  h.hrir(dir.data(), ears[0].data(), ears[1].data(), &dl, &dr);
  return ears;
}

/// ILD per octave band (analysed octaves), dB, left over right.
Bands ild(const Ears& e) {
  const Bands l = test::bandEnergies(e[0], kFs, true), r = test::bandEnergies(e[1], kFs, true);
  Bands out(0.f);
  for (int b = 0; b < kNumBands; ++b) out[b] = float(10.0 * std::log10(l[b] / r[b]));
  return out;
}

/// Mean |ILD error| per band over 96 directions: every 15 degrees of azimuth on the rings at
/// -30, 0, 30 and 60 degrees of elevation (all measured by KEMAR).
std::array<double, kNumBands> meanIldError(const AmbisonicBinauralDecoder& d, int order,
                                           const audio::Hrtf& hrtf) {
  std::array<double, kNumBands> sum{};
  int count = 0;
  for (int el : {-30, 0, 30, 60})
    for (int az = 0; az < 360; az += 15, ++count) {
      const Bands x = ild(planeWave(d, order, unit(az, el))), ref = ild(hrir(hrtf, unit(az, el)));
      for (int b = 0; b < kNumBands; ++b) sum[size_t(b)] += std::abs(x[b] - ref[b]);
    }
  for (double& s : sum) s /= count;
  return sum;
}

AmbisonicBinauralDecoder decoder(int order, const audio::Hrtf& hrtf, BinauralDecoderMethod m,
                                 bool covariance = false) {
  audio::BinauralDecoderOptions o;
  o.method = m;
  o.magLs.covarianceMaxOrder = covariance ? kMaxAmbisonicOrder : 0;
  return AmbisonicBinauralDecoder(order, hrtf, o);
}

std::string row(const char* what, const std::array<double, kNumBands>& v) {
  std::ostringstream s;
  s << what << std::fixed << std::setprecision(2);
  for (int b = kFirstBand; b < kNumBands; ++b) s << " " << v[size_t(b)];
  return s.str();
}

/// The interaural coherence of an isotropic diffuse field over the HRTF's measured directions
/// with their cell weights: per frequency bin |sum_q w_q L_q R_q*| / sqrt(sum_q w_q |L_q|^2
/// sum_q w_q |R_q|^2), averaged over each octave band.
struct DiffuseCoherence {
  static constexpr size_t kFft = 2048;
  std::vector<std::array<double, 3>> directions;
  std::vector<Ears> measured;  ///< the measurements' HRIR pairs
  std::vector<double> weights;

  explicit DiffuseCoherence(const audio::Hrtf& hrtf) {
    const size_t taps = size_t(hrtf.filterLength());
    for (size_t q = 0; q < hrtf.measurementCount(); ++q) {
      float u[3], dl, dr;
      Ears e{std::vector<float>(taps), std::vector<float>(taps)};
      hrtf.measurement(q, u, e[0].data(), e[1].data(), &dl, &dr);
      directions.push_back({u[0], u[1], u[2]});
      measured.push_back(std::move(e));
    }
    weights = cellWeights(directions, coarsestSpacing(directions), 100000);
  }
  std::array<float, 3> direction(size_t q) const {
    return {float(directions[q][0]), float(directions[q][1]), float(directions[q][2])};
  }
  /// The coherence per band of the ears ears(q) gives for each measured direction q.
  std::array<double, kNumBands> of(const std::function<Ears(size_t)>& ears) const {
    FftwRealTransforms fft(kFft);
    std::vector<double> ll(kFft / 2 + 1), rr(kFft / 2 + 1);
    std::vector<std::complex<double>> lr(kFft / 2 + 1);
    for (size_t q = 0; q < directions.size(); ++q) {
      const Ears e = ears(q);
      std::vector<std::complex<double>> x[2];
      for (int k = 0; k < 2; ++k) {
        std::fill(fft.time.p, fft.time.p + kFft, 0.f);
        std::copy(e[size_t(k)].begin(), e[size_t(k)].end(), fft.time.p);
        fftwf_execute(fft.fwd);
        for (size_t f = 0; f <= kFft / 2; ++f)
          x[k].emplace_back(fft.spec.p[f][0], fft.spec.p[f][1]);
      }
      for (size_t f = 1; f <= kFft / 2; ++f) {
        ll[f] += weights[q] * std::norm(x[0][f]);
        rr[f] += weights[q] * std::norm(x[1][f]);
        lr[f] += weights[q] * x[0][f] * std::conj(x[1][f]);
      }
    }
    return bandMeans(ll, rr, lr);
  }
  static std::array<double, kNumBands> bandMeans(const std::vector<double>& ll,
                                                 const std::vector<double>& rr,
                                                 const std::vector<std::complex<double>>& lr) {
    std::array<double, kNumBands> band{};
    for (int b = 0; b < kNumBands; ++b) {
      int count = 0;
      for (size_t f = 1; f < ll.size(); ++f) {
        const double hz = double(f) * kFs / double(kFft), fc = bandCentreExactHz(b);
        if (hz < fc / M_SQRT2 || hz >= fc * M_SQRT2) continue;
        band[size_t(b)] += std::abs(lr[f]) / std::sqrt(ll[f] * rr[f]);
        ++count;
      }
      band[size_t(b)] /= count;
    }
    return band;
  }
};

}  // namespace

TEST_CASE(
    "MagLS: above the cut-off the ILD follows the HRTF where the sampling decoder falls short",
    "[ambisonics][heavy]") {
  // Above kr = N an order-N decoder cannot match the complex HRTF; MagLS keeps its magnitudes.
  // Asserted: above f_c (orders 3 and 5) the mean ILD error per octave band is within the
  // issue's 2 dB, where the sampling decoder's exceeds it in some band; below f_c MagLS (least
  // squares there) is no worse than the sampling decoder but for 0.2 dB (its regularisation,
  // and the measured directions it is fitted to against the interpolated grid the sampling
  // decoder and the reference take).
  const audio::Hrtf hrtf = audio::Hrtf::load(kDefaultHrtfPath, kFs);
  for (int order : {1, 3, 5}) {
    const auto magLs =
        meanIldError(decoder(order, hrtf, BinauralDecoderMethod::kMagLs), order, hrtf);
    const auto sampling =
        meanIldError(decoder(order, hrtf, BinauralDecoderMethod::kSampling), order, hrtf);
    const auto covariance =
        meanIldError(decoder(order, hrtf, BinauralDecoderMethod::kMagLs, true), order, hrtf);
    WARN("order " << order << ", mean |ILD error| dB, 250 Hz .. 8 kHz:\n"
                  << row("  MagLS               ", magLs) << "\n"
                  << row("  MagLS + covariance  ", covariance) << "\n"
                  << row("  sampling            ", sampling));
    if (order == 1) continue;  // reported: order 1 keeps 4 dB at 8 kHz (docs/spatial.md)
    double samplingWorst = 0.0;
    for (int b = kFirstBand; b < kNumBands; ++b) {
      INFO("order " << order << " band " << b);
      if (bandCentreExactHz(b) < audio::kMagLsCutoffHz) {
        CHECK(magLs[size_t(b)] <= sampling[size_t(b)] + 0.2);
        continue;
      }
      CHECK(magLs[size_t(b)] <= 2.0);
      samplingWorst = std::max(samplingWorst, sampling[size_t(b)]);
    }
    CHECK(samplingWorst > 2.0);  // the bound tells the decoders apart
  }
}

TEST_CASE("MagLS: the covariance constraint restores the HRTF's diffuse-field coherence",
          "[ambisonics][heavy]") {
  // With Zaunschirm et al.'s constraint the decoded diffuse field's interaural coherence
  // equals the HRTF's in every octave centred above where it starts (min(f_c, f_N)), to
  // within 0.03 (the filters' truncation to filterLength() taps and the float spectra);
  // without it MagLS at order 1 leaves the ears far too coherent (the constraint's reason to
  // exist), at order 3 only a little.
  const audio::Hrtf hrtf = audio::Hrtf::load(kDefaultHrtfPath, kFs);
  const DiffuseCoherence field(hrtf);
  const auto target = field.of([&](size_t q) { return field.measured[q]; });
  for (int order : {1, 2, 3}) {
    std::array<double, kNumBands> ic[2];
    for (bool constrained : {false, true}) {
      const AmbisonicBinauralDecoder d =
          decoder(order, hrtf, BinauralDecoderMethod::kMagLs, constrained);
      ic[constrained] = field.of([&](size_t q) { return planeWave(d, order, field.direction(q)); });
    }
    WARN("order " << order << ", diffuse-field interaural coherence, 250 Hz .. 8 kHz:\n"
                  << row("  HRTF                ", target) << "\n"
                  << row("  MagLS               ", ic[0]) << "\n"
                  << row("  MagLS + covariance  ", ic[1]));
    for (int b = kFirstBand; b < kNumBands; ++b) {
      // The constraint starts at min(f_c, f_N): 624 / 1248 Hz at orders 1 / 2, f_c at 3.
      if (bandCentreExactHz(b) < audio::magLsCovarianceFromHz(order, {})) continue;
      INFO("order " << order << " band " << b);
      CHECK(std::abs(ic[1][size_t(b)] - target[size_t(b)]) <= 0.03);
    }
    if (order == 1) CHECK(ic[0][5] - target[5] > 0.3);  // 2 kHz: what the constraint corrects
  }
}

TEST_CASE("MagLS: below the lowest measured ring the decoded level stays bounded", "[ambisonics]") {
  // KEMAR has no measurement below -40 degrees; least squares alone is free to grow there. The
  // decoder fills the gap with what per-path binaural plays there (audio/magls_decoder.h).
  // Reported per order: the decoded broadband energy of both ears over azimuth against
  // per-path binaural's, dB. Asserted: within 1.5 dB from -30 to -75 degrees at every order up
  // to 7, as in the measured region; straight down within 7 dB: per-path binaural plays there
  // the time-domain blend of KEMAR's whole lowest ring (56 HRIRs of different delays, whose
  // high frequencies cancel), which no smooth order-N pattern follows to a point. Fitted to the
  // measurements alone the decoder gave +19 and +30 dB straight down at orders 5 and 7 (+5.5
  // and +3.7 dB with Tikhonov regularisation, lambda = 1e-2, instead).
  const audio::Hrtf hrtf = audio::Hrtf::load(kDefaultHrtfPath, kFs);
  for (int order : {1, 3, 5, 7}) {
    const AmbisonicBinauralDecoder d = decoder(order, hrtf, BinauralDecoderMethod::kMagLs);
    std::ostringstream line;
    line << "order " << order
         << ", decoded vs per-path energy at elevation -30 .. -90 dB:" << std::fixed
         << std::setprecision(1);
    for (int el : {-30, -45, -60, -75, -90}) {
      double decoded = 0, reference = 0;
      for (int az = 0; az < 360; az += 10) {
        const Ears x = planeWave(d, order, unit(az, el)), y = hrir(hrtf, unit(az, el));
        for (int e = 0; e < 2; ++e) {
          decoded += test::bandEnergies(x[size_t(e)], kFs, true).sum();
          reference += test::bandEnergies(y[size_t(e)], kFs, true).sum();
        }
      }
      const double db = 10 * std::log10(decoded / reference);
      line << " " << db;
      CHECK(std::abs(db) <= (el > -90 ? 1.5 : 7.0));
    }
    WARN(line.str());
  }
}

TEST_CASE("MagLS level weights: order 1 ignores them and order 3 fits the high band closer",
          "[ambisonics]") {
  // The weights (E / E_q)^alpha above f_c (audio/magls_decoder.h) apply from order 2 up: order
  // 1's filters equal those fitted with alpha = 0 exactly. At order 3 they lower the 8 kHz mean
  // |ILD error| over the 96 directions (1.68 dB with alpha = 0, 1.47 with 1/4: docs/spatial.md);
  // asserted lower by at least 0.1 dB, a deterministic fit (no noise), so any margin would do.
  const audio::Hrtf hrtf = audio::Hrtf::load(kDefaultHrtfPath, kFs);
  audio::BinauralDecoderOptions plain;
  plain.magLs.levelWeightExponent = 0.0;
  const AmbisonicBinauralDecoder weighted1(1, hrtf), plain1(1, hrtf, plain);
  for (size_t c = 0; c < 4; ++c)
    for (int e = 0; e < 2; ++e) CHECK(weighted1.filter(c, e) == plain1.filter(c, e));
  const auto weighted3 = meanIldError(AmbisonicBinauralDecoder(3, hrtf), 3, hrtf);
  const auto plain3 = meanIldError(AmbisonicBinauralDecoder(3, hrtf, plain), 3, hrtf);
  WARN("order 3 mean |ILD error| at 8 kHz: alpha 1/4 "
       << weighted3[kNumBands - 1] << " dB, alpha 0 " << plain3[kNumBands - 1] << " dB");
  CHECK(weighted3[kNumBands - 1] < plain3[kNumBands - 1] - 0.1);
}
