#include "synthesis/spatial_ir.h"

#include "synthesis/band_leveller.h"
#include "common/fftw_util.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <glm/geometric.hpp>
#include <numbers>
#include <stdexcept>

namespace dpc {

std::vector<glm::vec3> defaultSpatialDirections() {
  std::vector<glm::vec3> d;
  for (int i = 0; i < 6; ++i) {
    const float az = float(i) * std::numbers::pi_v<float> / 3.f;  // 0 = ahead, + = left
    d.push_back({std::cos(az), std::sin(az), 0.f});
  }
  d.push_back({0.f, 0.f, 1.f});
  const float el = -40.f * std::numbers::pi_v<float> / 180.f;
  d.push_back({std::cos(el), 0.f, std::sin(el)});
  return d;
}

namespace {
/// Whether frequency f (Hz) lies in what band b's analysis sees of its filter A_b: all of it,
/// except below the 63 Hz octave and above the 8 kHz octave, where A_b reaches on to 0 Hz and
/// Nyquist but an octave-band analysis does not.
bool inAnalysedOctave(int b, double f) {
  const double fc = bandCentreExactHz(b);
  if (b == 0) return f >= fc / std::numbers::sqrt2;
  if (b == kNumBands - 1) return f <= fc * std::numbers::sqrt2;
  return true;
}
}  // namespace


SpatialIrSynthesizer::~SpatialIrSynthesizer() = default;

SpatialIrSynthesizer::SpatialIrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume,
                                           double speedOfSound, uint64_t seed,
                                           std::vector<glm::vec3> directions,
                                           const std::vector<EarFilter>& filters, ExactFilter exact)
    : sampleRate_(sampleRate), directions_(std::move(directions)), exact_(std::move(exact)) {
  if (sampleRate <= 0 || !(lengthSeconds > 0.0) || !std::isfinite(lengthSeconds) ||
      !(roomVolume > 0.0) || !std::isfinite(roomVolume) || !(speedOfSound > 0.0) ||
      !std::isfinite(speedOfSound) || directions_.empty() ||
      filters.size() != directions_.size() || !exact_)
    throw std::invalid_argument("SpatialIrSynthesizer: inconsistent arguments");
  const size_t margin = size_t(sampleRate / 4);
  size_t maxFilter = 1;
  for (const EarFilter& f : filters) {
    if (f.left.empty() || f.right.empty() || f.left.size() >= margin || f.right.size() >= margin)
      throw std::invalid_argument("SpatialIrSynthesizer: filters must have 1 .. rate/4 taps");
    maxFilter = std::max({maxFilter, f.left.size(), f.right.size()});
  }
  length_ = size_t(std::ceil(lengthSeconds * sampleRate));
  const size_t nfft = nextPow2(length_ + margin + maxFilter);
  const size_t nbins = nfft / 2 + 1;
  const OctaveBandMasks masks(sampleRate, nfft);
  filterData_ = BandFilterData::compute(masks, nfft);
  const float scale = 1.f / float(nfft);

  FftwRealTransforms big(nfft);
  using Spectrum = std::vector<std::complex<float>>;  // layout-compatible with fftwf_complex
  Spectrum seqSpec(nbins);
  std::array<Spectrum, 2> earSpec{Spectrum(nbins), Spectrum(nbins)};

  // Each mask's span: sum of M_b^2 over the FFT bins.
  std::array<double, kNumBands> norm{};
  for (int b = 0; b < kNumBands; ++b)
    for (size_t k = 0; k < nbins; ++k)
      norm[size_t(b)] += double(masks.gain(b, k)) * masks.gain(b, k);
  // A band's energy in the energy response is its octave's (fc / sqrt 2 .. fc sqrt 2). The
  // extreme bands' filters reach beyond it (63 Hz down to 0 Hz, 8 kHz up to Nyquist); there
  // an IR carries the octave's spectral density on (as the mono synthesiser and
  // expectedBandAnalysisEnergy do), so those bands carry (span of M_b^2) / (octave width)
  // times the band energy: 2 at 63 Hz, 3.2 at 8 kHz and 48 kHz.
  for (int b = 0; b < kNumBands; ++b) {
    const double width = bandCentreExactHz(b) / std::numbers::sqrt2;
    densityGain_[size_t(b)] =
        (b == 0 || b == kNumBands - 1) ? norm[size_t(b)] * sampleRate / double(nfft) / width : 1.0;
  }
  auto spectrumOf = [&](const std::vector<float>& taps, Spectrum& out) {
    std::fill(big.time.p, big.time.p + nfft, 0.f);
    std::copy(taps.begin(), taps.end(), big.time.p);
    fftwf_execute_dft_r2c(big.fwd, big.time.p, big.spec.p);
    for (size_t k = 0; k < nbins; ++k) out[k] = {big.spec.p[k][0], big.spec.p[k][1]};
  };
  // Diffuse-field equalisation: the band energy of every direction's filter over the analysed
  // octave (inAnalysedOctave), averaged over directions and ears.
  kappa_.fill(0.0);
  earWeight_.assign(filters.size(), {});
  for (size_t d = 0; d < filters.size(); ++d)
    for (int ear = 0; ear < 2; ++ear) {
      spectrumOf(ear == 0 ? filters[d].left : filters[d].right, earSpec[size_t(ear)]);
      for (int b = 0; b < kNumBands; ++b) {
        double seen = 0.0, seenNorm = 0.0;
        for (size_t k = 0; k < nbins; ++k) {
          if (!inAnalysedOctave(b, double(k) * sampleRate / double(nfft))) continue;
          const double m2 = double(masks.gain(b, k)) * masks.gain(b, k);
          seen += m2 * double(std::norm(earSpec[size_t(ear)][k]));
          seenNorm += m2;
        }
        earWeight_[d][size_t(ear)][b] = float(seen / seenNorm);
        kappa_[size_t(b)] += seen / seenNorm / double(2 * filters.size());
      }
    }
  for (auto& perEar : earWeight_)
    for (Bands& w : perEar)
      for (int b = 0; b < kNumBands; ++b) w[b] = float(double(w[b]) / kappa_[size_t(b)]);

  // Per direction: its own Dirac sequence, through A_b and the direction's filter.
  bands_.resize(directions_.size());
  for (size_t d = 0; d < directions_.size(); ++d) {
    const std::vector<float> seq =
        diracSequence(sampleRate, length_, roomVolume, speedOfSound,
                      IrSynthesizer::kMaxDensityPerSecond, hashCombine(seed, d + 1));
    spectrumOf(seq, seqSpec);
    std::array<std::vector<float>, BandEnvelope::kRealisedBands> measured;
    for (int b = 0; b < BandEnvelope::kRealisedBands; ++b) {
      for (size_t k = 0; k < nbins; ++k) {
        const float m = masks.gain(b, k);
        const std::complex<float> v = seqSpec[k] * (m * m * m * scale);
        big.band.p[k][0] = v.real();
        big.band.p[k][1] = v.imag();
      }
      fftwf_execute_dft_c2r(big.inv, big.band.p, big.time.p);
      measured[size_t(b)].assign(big.time.p, big.time.p + length_);
    }
    envelopes_.push_back(
        std::make_unique<BandEnvelope>(sampleRate, seq, length_, filterData_, measured));
    for (int ear = 0; ear < 2; ++ear) {
      spectrumOf(ear == 0 ? filters[d].left : filters[d].right, earSpec[size_t(ear)]);
      for (int b = 0; b < kNumBands; ++b) {
        const float eq = float(std::sqrt(densityGain_[size_t(b)] / kappa_[size_t(b)]));
        for (size_t k = 0; k < nbins; ++k) {
          const float g = masks.gain(b, k) * masks.gain(b, k) * scale * eq;
          const std::complex<float> v = g * seqSpec[k] * earSpec[size_t(ear)][k];
          big.band.p[k][0] = v.real();
          big.band.p[k][1] = v.imag();
        }
        fftwf_execute_dft_c2r(big.inv, big.band.p, big.time.p);
        bands_[d][size_t(ear)][size_t(b)].assign(big.time.p, big.time.p + length_);
      }
    }
  }

  // The omnidirectional low bands: one more sequence, through A_b only (no ear filter).
  {
    const std::vector<float> seq =
        diracSequence(sampleRate, length_, roomVolume, speedOfSound,
                      IrSynthesizer::kMaxDensityPerSecond, hashCombine(seed, 0x0a0a0a0aULL));
    spectrumOf(seq, seqSpec);
    std::array<std::vector<float>, BandEnvelope::kRealisedBands> measured;
    for (int b = 0; b < kDirectionalFromBand; ++b) {
      for (int pass = 0; pass < 2; ++pass) {
        for (size_t k = 0; k < nbins; ++k) {
          const float m = masks.gain(b, k);
          const float g = (pass == 0 ? m * m : m * m * m) * scale;
          big.band.p[k][0] = seqSpec[k].real() * g;
          big.band.p[k][1] = seqSpec[k].imag() * g;
        }
        fftwf_execute_dft_c2r(big.inv, big.band.p, big.time.p);
        if (pass == 0) {
          omniBands_[size_t(b)].assign(big.time.p, big.time.p + length_);
          const float density = float(std::sqrt(densityGain_[size_t(b)]));
          for (float& x : omniBands_[size_t(b)]) x *= density;
        }
        else if (b < BandEnvelope::kRealisedBands)
          measured[size_t(b)].assign(big.time.p, big.time.p + length_);
      }
    }
    omniEnvelope_ = std::make_unique<BandEnvelope>(sampleRate, seq, length_, filterData_, measured);
    omniEnergy_ = EnergyResponse(lengthSeconds, 1e-3);
  }

  // Band filters a_b for the direct sound (zero phase, centred), as in IrSynthesizer.
  filterCentre_ = margin / 2;
  for (int b = 0; b < kNumBands; ++b) {
    for (size_t k = 0; k < nbins; ++k) {
      big.band.p[k][0] = masks.gain(b, k) * masks.gain(b, k) * scale;
      big.band.p[k][1] = 0.f;
    }
    fftwf_execute_dft_c2r(big.inv, big.band.p, big.time.p);
    bandFilter_[size_t(b)].assign(margin, 0.f);
    for (size_t i = 0; i < margin; ++i)
      bandFilter_[size_t(b)][i] = big.time.p[(i + nfft - filterCentre_) % nfft];
  }

  // Direct-sound convolution: band-shaped impulse (margin) * filter (< margin).
  fft_ = std::make_unique<FftwRealTransforms>(nextPow2(2 * margin));
  directFft_ = fft_->n;
  exactScratch_.left.reserve(margin);
  exactScratch_.right.reserve(margin);
  const OctaveBandMasks directMasks(sampleRate, fft_->n);
  directMask2_.resize(fft_->n / 2 + 1);
  for (size_t k = 0; k < directMask2_.size(); ++k)
    for (int b = 0; b < kNumBands; ++b) {
      const bool seen = inAnalysedOctave(b, double(k) * sampleRate / double(fft_->n));
      const float m2 = seen ? directMasks.gain(b, k) * directMasks.gain(b, k) : 0.f;
      directMask2_[k][b] = m2;
      directNorm_[size_t(b)] += double(m2);
    }
  leveller_ = std::make_unique<BandLeveller>(
      sampleRate, length_, kDirectionalFromBand,
      BandLeveller::densityStart(sampleRate, roomVolume, speedOfSound, kLevelFromPulses));
}

void SpatialIrSynthesizer::synthesize(const DirectionalEnergyResponse& energy,
                                      const DirectSound& direct, float* left, float* right) {
  std::fill(left, left + length_, 0.f);
  std::fill(right, right + length_, 0.f);
  const size_t count = std::min(energy.directionCount(), directions_.size());
  for (size_t d = 0; d < count; ++d) envelopes_[d]->compute(energy.response(d));
  // Omnidirectional low bands: the directions' responses summed (same bins as theirs).
  if (omniEnergy_.binCount() != energy.response(0).binCount())
    omniEnergy_ =
        EnergyResponse(double(energy.response(0).binCount()) * energy.response(0).binSeconds(),
                       energy.response(0).binSeconds());
  omniEnergy_.clear();
  for (size_t d = 0; d < count; ++d)
    for (size_t k = 0; k < omniEnergy_.binCount(); ++k)
      for (int b = 0; b < kDirectionalFromBand; ++b)
        omniEnergy_.bins()[k][b] += energy.response(d).bins()[k][b];
  omniEnvelope_->compute(omniEnergy_);
  std::array<const float*, kNumBands> omni{};
  for (int b = 0; b < kDirectionalFromBand; ++b) omni[size_t(b)] = omniBands_[size_t(b)].data();
  // Cache-blocked: each output block stays in L1 while all K x 2 x 8 band signals stream
  // through it once (the loop is memory-bound: the band signals are K x 16 x length floats).
  constexpr size_t kBlock = 2048;
  for (size_t begin = 0; begin < length_; begin += kBlock) {
    const size_t end = std::min(length_, begin + kBlock);
    for (size_t d = 0; d < count; ++d)
      for (int ear = 0; ear < 2; ++ear) {
        std::array<const float*, kNumBands> bands;
        for (int b = 0; b < kNumBands; ++b)
          bands[size_t(b)] = bands_[d][size_t(ear)][size_t(b)].data();
        envelopes_[d]->accumulateRange(bands, ear == 0 ? left : right, begin, end, 1.f,
                                       kDirectionalFromBand, kNumBands);
      }
    for (int ear = 0; ear < 2; ++ear)
      omniEnvelope_->accumulateRange(omni, ear == 0 ? left : right, begin, end, 1.f, 0,
                                     kDirectionalFromBand);
  }
  if (direct.visible) addDirect(direct, energy.toListener(direct.direction), left, right);
  // Each ear levelled to its own target: sum_d E_d,b x the ear filter's band energy for
  // direction d (diffuse-field equalised), plus the direct sound through its exact filter.
  for (int ear = 0; ear < 2; ++ear) {
    leveller_->clearTargets();
    for (size_t d = 0; d < count; ++d)
      leveller_->addResponse(energy.response(d), earWeight_[d][size_t(ear)]);
    if (direct.visible) {
      Bands e;
      for (int b = 0; b < kNumBands; ++b) e[b] = direct.intensity[b] * directWeight_[size_t(ear)][b];
      leveller_->addDirect(direct.delaySeconds, e);
    }
    leveller_->apply(ear == 0 ? left : right, kLevelTolerance, kLevelMaxBoost);
  }
}

void SpatialIrSynthesizer::addDirect(const DirectSound& direct, const glm::vec3& dir, float* left,
                                     float* right) {
  exact_(glm::normalize(dir), exactScratch_);
  const size_t n = fft_->n, nbins = n / 2 + 1, margin = bandFilter_[0].size();
  // The band-shaped impulse: sum_b amp_b a_b, diffuse-field equalised, time 0 at centre.
  std::fill(fft_->time.p, fft_->time.p + n, 0.f);
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const float amp =
        float(std::sqrt(double(direct.intensity[b]) * densityGain_[bi] /
                        (filterData_.share[bi] * kappa_[bi])));
    for (size_t i = 0; i < margin; ++i) fft_->time.p[i] += amp * bandFilter_[bi][i];
  }
  fftwf_execute_dft_r2c(fft_->fwd, fft_->time.p, fft_->spec.p);
  const long n0 = std::lround(double(direct.delaySeconds) * sampleRate_) - long(filterCentre_);
  for (int ear = 0; ear < 2; ++ear) {
    const std::vector<float>& h = ear == 0 ? exactScratch_.left : exactScratch_.right;
    std::fill(fft_->time.p, fft_->time.p + n, 0.f);
    std::copy(h.begin(), h.begin() + long(std::min(h.size(), n)), fft_->time.p);
    fftwf_execute_dft_r2c(fft_->fwd, fft_->time.p, fft_->band.p);
    // The exact filter's band energies (diffuse-field equalised) for this ear's target.
    Bands& w = directWeight_[size_t(ear)];
    for (int b = 0; b < kNumBands; ++b) w[b] = 0.f;
    {
      std::array<double, kNumBands> e{};
      for (size_t k = 0; k < nbins; ++k) {
        const double p =
            double(fft_->band.p[k][0]) * fft_->band.p[k][0] +
            double(fft_->band.p[k][1]) * fft_->band.p[k][1];
        for (int b = 0; b < kNumBands; ++b) e[size_t(b)] += p * double(directMask2_[k][b]);
      }
      for (int b = 0; b < kNumBands; ++b)
        w[b] = float(e[size_t(b)] / (directNorm_[size_t(b)] * kappa_[size_t(b)]));
    }
    const float scale = 1.f / float(n);
    for (size_t k = 0; k < nbins; ++k) {
      const float ar = fft_->spec.p[k][0], ai = fft_->spec.p[k][1];
      const float hr = fft_->band.p[k][0], hi = fft_->band.p[k][1];
      fft_->band.p[k][0] = (ar * hr - ai * hi) * scale;
      fft_->band.p[k][1] = (ar * hi + ai * hr) * scale;
    }
    fftwf_execute_dft_c2r(fft_->inv, fft_->band.p, fft_->time.p);
    float* out = ear == 0 ? left : right;
    const size_t used = margin + h.size();
    for (size_t i = 0; i < used && i < n; ++i) {
      const long t = n0 + long(i);
      if (t >= 0 && t < long(length_)) out[t] += fft_->time.p[i];
    }
  }
}

}  // namespace dpc
