#include "synthesis/band_leveller.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "common/fftw_util.h"
#include "common/wide_vectors.h"
#include "synthesis/band_filters.h"

namespace dpc {

namespace {

/// Four analysis filters side by side, one per lane (3 biquads each, transposed direct form
/// II, coefficients c[coef][section] with coef = b0, b1, b2, a1, a2), each on its own input
/// in[lane][from, length), from a multiple of w, started at rest there: each lane's squared
/// output summed over bins of w samples into e[lane][bin] (bins before from: 0). The
/// recursions are serial per lane; side by side they run in parallel.
DPC_WIDE_VECTORS
void analysedEnergy4(const Double4 (&c)[5][3], const float* const (&in)[4], size_t from,
                     size_t length, size_t w, double* const (&e)[4]) {
  Double4 s1[3] = {}, s2[3] = {};
  const Double4 tiny = {1e-150, 1e-150, 1e-150, 1e-150}, zero = {};
  for (size_t lane = 0; lane < 4; ++lane) std::fill(e[lane], e[lane] + from / w, 0.0);
  for (size_t begin = from; begin < length; begin += w) {
    const size_t end = std::min(length, begin + w);
    Double4 sum = {};
    for (size_t n = begin; n < end; ++n) {
      Double4 x = {double(in[0][n]), double(in[1][n]), double(in[2][n]), double(in[3][n])};
      for (size_t k = 0; k < 3; ++k) {
        const Double4 y = c[0][k] * x + s1[k];
        s1[k] = c[1][k] * x - c[3][k] * y + s2[k];
        s2[k] = c[2][k] * x - c[4][k] * y;
        x = y;
      }
      sum += x * x;
    }
    for (size_t lane = 0; lane < 4; ++lane) e[lane][begin / w] = sum[lane];
    // Values far below float range would become denormals (about 100 times slower).
    for (size_t k = 0; k < 3; ++k) {
      s1[k] = (s1[k] < tiny && s1[k] > -tiny) ? zero : s1[k];
      s2[k] = (s2[k] < tiny && s2[k] > -tiny) ? zero : s2[k];
    }
  }
}

/// The energy that band b's analysis filter puts out for white noise of unit spectral density
/// (a response's band value, synthesis/band_filters.h) through A_b: the energy of a_b
/// (impulse, time 0 at its centre) through the filter, rung out.
double analysedPerOctave(const OctaveBandPass& filter, const std::vector<float>& impulse,
                         int sampleRate) {
  const size_t taps = impulse.size();
  OctaveBandPass::State st{};
  double e = 0.0;
  for (size_t n = 0; n < taps + bandFilterTaps(sampleRate); ++n) {
    const double y = filter.step(n < taps ? impulse[n] : 0.f, st);
    e += y * y;
  }
  return e;
}

}  // namespace

BandLeveller::~BandLeveller() = default;

size_t BandLeveller::densityStart(int sampleRate, double roomVolume, double speedOfSound,
                                  double pulses) {
  // mu(t) = 4 pi c^3 t^2 / V >= pulses per bin
  const double mu = pulses / kBinSeconds;
  const double start =
      std::sqrt(mu * roomVolume /
                (4.0 * std::numbers::pi * speedOfSound * speedOfSound * speedOfSound)) *
      sampleRate;
  // A room too large (or c too small) for the density to reach `pulses` within any IR: never.
  constexpr double kNever = 1e15;
  return start >= 0.0 ? size_t(std::min(start, kNever)) : size_t(kNever);
}

BandLeveller::BandLeveller(int sampleRate, size_t length, int firstBand, size_t startSample)
    : sampleRate_(sampleRate), length_(length), firstBand_(firstBand), start_(startSample) {
  if (sampleRate <= 0 || length == 0 || firstBand < 0 || firstBand >= kNumBands)
    throw std::invalid_argument("BandLeveller: rate, length and first band must be valid");
  // The zero-phase filters' reach: of the levelled bands' filters only.
  const size_t taps = bandFilterTapsFrom(sampleRate, firstBand);
  fft_ = std::make_unique<FftwRealTransforms>(smoothFftSize(length + taps));
  const size_t nfft = fft_->n, nbins = nfft / 2 + 1;
  const OctaveBandMasks masks(sampleRate, nfft);
  const DirectSoundFilter impulses(masks, *fft_, taps);
  const float scale = 1.f / float(nfft);
  binSamples_ = std::max<size_t>(1, size_t(std::lround(kBinSeconds * sampleRate)));
  const size_t bins = (length + binSamples_ - 1) / binSamples_;
  for (int b = firstBand; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    target_[bi].assign(bins, 0.0);
    actual_[bi].assign(bins, 0.0);
    part_[bi].assign(length, 0.f);
    filter_[bi].resize(nbins);
    for (size_t k = 0; k < nbins; ++k) filter_[bi][k] = masks.gain(b, k) * masks.gain(b, k) * scale;
    analysed_[bi] = analysableBand(b, sampleRate);
    if (!analysed_[bi]) continue;
    analysis_[bi] = OctaveBandPass::design(bandCentreExactHz(b), sampleRate);
    analysedPerOctave_[bi] = analysedPerOctave(analysis_[bi], impulses.band(b), sampleRate);
  }
  gain_.assign(bins, 1.f);
  unusedEnergy_.assign(bins, 0.0);
}

void BandLeveller::clearTargets() {
  for (int b = firstBand_; b < kNumBands; ++b)
    std::fill(target_[size_t(b)].begin(), target_[size_t(b)].end(), 0.0);
  directSample_ = -1;
}

void BandLeveller::addResponse(const EnergyResponse& energy, const Bands& weight) {
  const double perBin = energy.binSeconds() * sampleRate_;
  const size_t nb = gain_.size();
  for (size_t k = 0; k < energy.binCount(); ++k) {
    const size_t j = std::min(nb - 1, size_t((double(k) + 0.5) * perBin) / binSamples_);
    for (int b = firstBand_; b < kNumBands; ++b)
      target_[size_t(b)][j] += double(std::max(0.f, energy.bins()[k][b])) * double(weight[b]);
  }
}

void BandLeveller::binResponse(const EnergyResponse& energy, std::vector<Bands>& out) const {
  const double perBin = energy.binSeconds() * sampleRate_;
  const size_t nb = gain_.size();
  out.resize(nb);
  std::fill(out.begin(), out.end(), Bands(0.f));
  for (size_t k = 0; k < energy.binCount(); ++k) {
    const size_t j = std::min(nb - 1, size_t((double(k) + 0.5) * perBin) / binSamples_);
    for (int b = firstBand_; b < kNumBands; ++b) out[j][b] += std::max(0.f, energy.bins()[k][b]);
  }
}

void BandLeveller::addBinned(std::span<const Bands> binned, const Bands& weight) {
  for (size_t j = 0; j < std::min(binned.size(), gain_.size()); ++j)
    for (int b = firstBand_; b < kNumBands; ++b)
      target_[size_t(b)][j] += double(binned[j][b]) * double(weight[b]);
}

void BandLeveller::addDirect(double delaySeconds, const Bands& energy) {
  const long n0 = std::lround(delaySeconds * sampleRate_);
  if (n0 < 0 || size_t(n0) >= length_) return;
  if (directSample_ < 0 || n0 < directSample_) directSample_ = n0;  // the first arrival's
  for (int b = firstBand_; b < kNumBands; ++b)
    target_[size_t(b)][size_t(n0) / binSamples_] += std::max(0.f, energy[b]);
}

int BandLeveller::levelledBands(std::array<int, kNumBands>& bands,
                                std::array<size_t, kNumBands>& first) const {
  const size_t w = binSamples_;
  const size_t nb = actual_[size_t(firstBand_)].size();
  int count = 0;
  for (int b = firstBand_; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    if (!analysed_[bi]) continue;
    size_t f = directSample_ >= 0 ? std::min(nb, size_t(directSample_) / w) : nb;
    for (size_t j = 0; j < f; ++j)
      if (target_[bi][j] > 0.0) {
        f = j;
        break;
      }
    f = std::max(f + 2, start_ / w + 1);
    if (f >= nb) continue;
    first[bi] = f;
    bands[size_t(count++)] = b;
  }
  return count;
}

void BandLeveller::splitBands(const std::array<int, kNumBands>& bands, int count) {
  FftwRealTransforms& c = *fft_;
  const size_t nbins = c.n / 2 + 1;
  for (int i = 0; i < count; ++i) {
    const size_t bi = size_t(bands[size_t(i)]);
    const auto& f = filter_[bi];
    for (size_t k = 0; k < nbins; ++k) {
      c.band.p[k][0] = c.spec.p[k][0] * f[k];
      c.band.p[k][1] = c.spec.p[k][1] * f[k];
    }
    fftwf_execute(c.inv);
    std::copy(c.time.p, c.time.p + length_, part_[bi].begin());
  }
}

void BandLeveller::measureBands(const std::array<int, kNumBands>& bands,
                                const std::array<size_t, kNumBands>& first, int count) {
  // Splatter sits mostly low in A_b's span, inside the analysed octave, so A_b's reach up to
  // Nyquist must not excuse it. Four bands at a time in vector lanes, each group's filters
  // started at rest kSettlePeriods periods of its lowest band's centre before the first bin a
  // comparison window of its bands reads: the bins before are never compared, and what the
  // filters' start from rest leaves out has rung down below -100 dB by then.
  for (int g = 0; g < count; g += 4) {
    const int last = std::min(count, g + 4);
    size_t firstRead = actual_[size_t(bands[size_t(g)])].size();
    for (int i = g; i < last; ++i) firstRead = std::min(firstRead, first[size_t(bands[size_t(i)])]);
    const double settle = kSettlePeriods * sampleRate_ / bandCentreExactHz(bands[size_t(g)]);
    const size_t before = kWindowBins / 2 + size_t(std::ceil(settle / double(binSamples_)));
    const size_t from = (firstRead > before ? firstRead - before : 0) * binSamples_;
    Double4 coef[5][3] = {};
    const float* in[4];
    double* e[4];
    for (size_t lane = 0; lane < 4; ++lane) {
      const int i = g + int(lane);
      // A lane without a band filters the first band's part with zero coefficients.
      const size_t bi = size_t(bands[size_t(i < count ? i : g)]);
      in[lane] = part_[bi].data();
      e[lane] = i < count ? actual_[bi].data() : unusedEnergy_.data();
      if (i >= count) continue;
      for (size_t k = 0; k < 3; ++k) {
        const Biquad& q = analysis_[bi].sections[k];
        coef[0][k][lane] = q.b0;
        coef[1][k][lane] = q.b1;
        coef[2][k][lane] = q.b2;
        coef[3][k][lane] = q.a1;
        coef[4][k][lane] = q.a2;
      }
    }
    analysedEnergy4(coef, in, from, length_, binSamples_, e);
  }
}

bool BandLeveller::bandGains(size_t bi, size_t first, double tolerance, double maxBoost) {
  const auto& target = target_[bi];
  const auto& actual = actual_[bi];
  const double ratio = analysedPerOctave_[bi];
  const size_t nb = actual.size(), half = kWindowBins / 2;
  bool any = false;
  for (size_t j = 0; j < nb; ++j) {
    gain_[j] = 1.f;
    if (j < first) continue;
    double want = 0.0, got = 0.0;
    for (size_t q = j >= half ? j - half : 0; q < std::min(nb, j + half + 1); ++q) {
      want += target[q];
      got += actual[q];
    }
    const double high = tolerance * ratio * want;
    if (!std::isfinite(want)) continue;  // an unbounded target gives no level to aim at
    if (got > high) {
      gain_[j] = float(std::sqrt(high / got));
    } else if (maxBoost > 1.0 && got > 0.0 && got * tolerance < ratio * want) {
      gain_[j] = float(std::min(maxBoost, std::sqrt(ratio * want / (tolerance * got))));
    }
    any = any || gain_[j] != 1.f;
  }
  return any;
}

void BandLeveller::applyGains(size_t bi, float* ir) const {
  // g constant before the first centre and after the last, segment by segment between
  // centres; segments at unit gain skipped.
  const size_t w = binSamples_, nb = gain_.size();
  const double invW = 1.0 / double(w);
  const float* x = part_[bi].data();
  const size_t firstCentre = w / 2;  // samples n with (n + 0.5) / w - 0.5 <= 0 come before
  for (size_t n = 0; n < std::min(length_, firstCentre); ++n)
    if (gain_[0] != 1.f) ir[n] += float((double(gain_[0]) - 1.0) * x[n]);
  for (size_t j = 0; j + 1 < nb; ++j) {
    if (gain_[j] == 1.f && gain_[j + 1] == 1.f) continue;
    const double g0 = gain_[j], g1 = gain_[j + 1];
    const size_t n0 = std::min(length_, j * w + firstCentre);
    const size_t n1 = std::min(length_, (j + 1) * w + firstCentre);
    // g(n) - 1 = a + slope (n - n0), float so that the loop vectorises.
    const double t0 = (double(n0) + 0.5) * invW - 0.5 - double(j);
    const float a = float((1.0 - t0) * g0 + t0 * g1 - 1.0), slope = float((g1 - g0) * invW);
    for (size_t n = n0; n < n1; ++n) ir[n] += (a + slope * float(n - n0)) * x[n];
  }
  const size_t lastStart = std::min(length_, (nb - 1) * w + firstCentre);
  if (gain_[nb - 1] != 1.f)
    for (size_t n = lastStart; n < length_; ++n)
      ir[n] += float((double(gain_[nb - 1]) - 1.0) * x[n]);
}

void BandLeveller::apply(float* ir, double tolerance, double maxBoost) {
  std::array<Levelling, kNumBands> perBand;
  perBand.fill({tolerance, maxBoost});
  apply(ir, perBand);
}

void BandLeveller::apply(float* ir, const std::array<Levelling, kNumBands>& perBand) {
  std::array<int, kNumBands> bands{};
  std::array<size_t, kNumBands> first{};
  int count = 0;
  for (int i = 0, all = levelledBands(bands, first); i < all; ++i)
    if (perBand[size_t(bands[size_t(i)])].levelled) bands[size_t(count++)] = bands[size_t(i)];
  if (count == 0) return;
  FftwRealTransforms& c = *fft_;
  std::fill(c.time.p, c.time.p + c.n, 0.f);
  std::copy(ir, ir + length_, c.time.p);
  fftwf_execute(c.fwd);
  splitBands(bands, count);
  measureBands(bands, first, count);
  for (int i = 0; i < count; ++i) {
    const size_t bi = size_t(bands[size_t(i)]);
    const Levelling& l = perBand[bi];
    if (bandGains(bi, first[bi], l.tolerance, l.maxBoost)) applyGains(bi, ir);
  }
}

}  // namespace dpc
