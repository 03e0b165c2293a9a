#include "synthesis/spatial_synthesizer.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>

#include "common/durations.h"
#include "common/random.h"
#include "synthesis/band_leveller.h"
#include "synthesis/dirac_sequence.h"
#include "synthesis/filter_shape.h"
#include "synthesis/late_rotation.h"
#include "synthesis/mono_synthesizer.h"

namespace dpc {

SpatialIrSynthesizer::~SpatialIrSynthesizer() = default;

SpatialIrSynthesizer::SpatialIrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume,
                                           double speedOfSound, uint64_t seed,
                                           std::vector<glm::vec3> directions,
                                           const std::vector<DirectionFilter>& filters,
                                           ExactFilter exact, Reference reference)
    : sampleRate_(sampleRate),
      reference_(reference),
      directions_(std::move(directions)),
      exact_(std::move(exact)) {
  if (sampleRate <= 0 || !(lengthSeconds > 0.0) || !std::isfinite(lengthSeconds) ||
      !(roomVolume > 0.0) || !std::isfinite(roomVolume) || !(speedOfSound > 0.0) ||
      !std::isfinite(speedOfSound) || directions_.empty() || filters.size() != directions_.size() ||
      !exact_)
    throw std::invalid_argument("SpatialIrSynthesizer: inconsistent arguments");
  const size_t margin = bandFilterTaps(sampleRate);
  channels_ = filters[0].channels.size();
  const size_t maxFilter = longestFilter(filters, channels_, margin);
  length_ = stepsCovering(lengthSeconds, 1.0 / sampleRate);
  FftwRealTransforms big(nextPow2(length_ + margin + maxFilter));
  const OctaveBandMasks masks(sampleRate, big.n);
  filterData_ = BandFilterData::compute(masks, big.n);
  equaliseDiffuseField(filters, masks, big);
  // Per direction: its own Dirac sequence, through A_b and the direction's filters.
  gainsOnly_ = maxFilter == 1;
  if (!gainsOnly_ && reference_ == Reference::kChannelAverage) reverbDelay_ = fieldDelay(filters);
  if (gainsOnly_) directionScratch_.assign(length_, 0.f);
  bands_ = std::make_shared<std::vector<std::vector<std::array<std::vector<float>, kNumBands>>>>(
      directions_.size());
  omniBands_ = std::make_shared<std::array<std::vector<float>, kNumBands>>();
  gains_.resize(directions_.size());
  for (size_t d = 0; d < directions_.size(); ++d)
    directionBands(d,
                   diracSequence(sampleRate, length_, roomVolume, speedOfSound, kMaxPulseDensity,
                                 hashCombine(seed, d + 1)),
                   filters[d], masks, big);
  omniBands(diracSequence(sampleRate, length_, roomVolume, speedOfSound, kMaxPulseDensity,
                          hashCombine(seed, 0x0a0a0a0aULL)),
            masks, big, lengthSeconds);
  if (channels_ == 2 && maxFilter > 1 && reference_ == Reference::kChannelAverage) {
    coherence_ =
        std::make_shared<const CoherenceMatch>(filters, exact_, sampleRate, kDirectionalFromBand);
    for (std::vector<float>& e : earScratch_) e.assign(length_, 0.f);
    directionTotals_.resize(directions_.size());
    bandEnergy_.resize(directions_.size());
  }
  direct_ = std::make_shared<const DirectSoundFilter>(masks, big, margin);
  prepareDirect(margin, maxFilter);
  levelStart_ = BandLeveller::densityStart(sampleRate, roomVolume, speedOfSound, kLevelFromPulses);
  rotationFrom_ = BandLeveller::densityStart(sampleRate, roomVolume, speedOfSound,
                                             kIndependentFromDensity * BandLeveller::kBinSeconds);
  fixed_.assign(channels_, std::vector<float>(length_ + reverbDelay_));
  fixedTo_.resize(channels_);
  fixedFrom_.resize(channels_);
  channelLevelling_ = std::make_shared<ChannelLevelling>(
      sampleRate, length_, IrSynthesizer::kFirstLevelledBand, windowBands());
  levelledFrom_ = lastWindowLevelledBand(channels_) + 1;  // the bands the windows leave
  levellers_.push_back(
      std::make_shared<BandLeveller>(sampleRate, length_, levelledFrom_, levelStart_));
  binned_.assign(directions_.size(), std::vector<Bands>(levellers_[0]->bins()));
}

SpatialIrSynthesizer::SpatialIrSynthesizer(const SpatialIrSynthesizer&) = default;

std::unique_ptr<SpatialIrSynthesizer> SpatialIrSynthesizer::workspaceCopy() const {
  std::unique_ptr<SpatialIrSynthesizer> copy(new SpatialIrSynthesizer(*this));
  copy->fft_ = std::make_shared<FftwRealTransforms>(fft_->n);
  copy->levellers_.assign(
      1, std::make_shared<BandLeveller>(sampleRate_, length_, levelledFrom_, levelStart_));
  copy->parallel_ = {};
  if (channelLevelling_)
    copy->channelLevelling_ = std::make_shared<ChannelLevelling>(
        sampleRate_, length_, IrSynthesizer::kFirstLevelledBand, windowBands());
  return copy;
}

int SpatialIrSynthesizer::lastWindowLevelledBandOf(size_t c) const {
  return c == 0 && reference_ == Reference::kFirstChannelPressure
             ? kLastFewChannelsWindowBand
             : lastWindowLevelledBand(channels_);
}

std::vector<int> SpatialIrSynthesizer::windowBands() const {
  std::vector<int> bands(channels_);
  for (size_t c = 0; c < channels_; ++c) bands[c] = lastWindowLevelledBandOf(c);
  return bands;
}

void SpatialIrSynthesizer::setParallelLevelling(int workers, ParallelFor parallel) {
  const size_t w =
      std::clamp<size_t>(size_t(std::max(workers, 1)), 1, std::max<size_t>(1, channels_));
  while (levellers_.size() < w)
    levellers_.push_back(
        std::make_shared<BandLeveller>(sampleRate_, length_, levelledFrom_, levelStart_));
  levellers_.resize(w);
  if (channelLevelling_) channelLevelling_->setWorkers(w, parallel);
  parallel_ = std::move(parallel);
}

void SpatialIrSynthesizer::spectrumOf(FftwRealTransforms& fft, const std::vector<float>& taps,
                                      Spectrum& out) const {
  std::fill(fft.time.p, fft.time.p + fft.n, 0.f);
  std::copy(taps.begin(), taps.end(), fft.time.p);
  fftwf_execute_dft_r2c(fft.fwd, fft.time.p, fft.spec.p);
  for (size_t k = 0; k < fft.n / 2 + 1; ++k) out[k] = {fft.spec.p[k][0], fft.spec.p[k][1]};
}

void SpatialIrSynthesizer::equaliseDiffuseField(const std::vector<DirectionFilter>& filters,
                                                const OctaveBandMasks& masks,
                                                FftwRealTransforms& fft) {
  // The band energy of every direction's filters over the analysed octave (inAnalysedOctave),
  // averaged over directions and channels.
  const size_t nbins = fft.n / 2 + 1;
  Spectrum spec(nbins);
  kappa_.fill(0.0);
  channelWeight_.assign(filters.size(), std::vector<Bands>(channels_));
  for (size_t d = 0; d < filters.size(); ++d)
    for (size_t c = 0; c < channels_; ++c) {
      const std::vector<float>& taps = filters[d].channels[c];
      if (taps.size() > 1) spectrumOf(fft, taps, spec);
      for (int b = 0; b < kNumBands; ++b) {
        // A one-tap filter (a gain g: panning, Ambisonics) has the flat spectrum g^2.
        double seen = taps.size() == 1 ? double(taps[0]) * taps[0] : 0.0, seenNorm = 1.0;
        if (taps.size() > 1) {
          seenNorm = 0.0;
          for (size_t k = 0; k < nbins; ++k) {
            if (!inAnalysedOctave(b, double(k) * sampleRate_ / double(fft.n))) continue;
            const double m2 = double(masks.gain(b, k)) * masks.gain(b, k);
            seen += m2 * double(std::norm(spec[k]));
            seenNorm += m2;
          }
        }
        channelWeight_[d][c][b] = float(seen / seenNorm);
        if (reference_ == Reference::kChannelAverage)
          kappa_[size_t(b)] += seen / seenNorm / double(channels_ * filters.size());
        else if (reference_ == Reference::kChannelSum || c == 0)
          kappa_[size_t(b)] += seen / seenNorm / double(filters.size());
      }
    }
  for (auto& perChannel : channelWeight_)
    for (Bands& w : perChannel)
      for (int b = 0; b < kNumBands; ++b) w[b] = float(double(w[b]) / kappa_[size_t(b)]);
  // The levellers' weights: what their views see of each filter, not the flat band model
  // (synthesis/filter_shape.h).
  std::array<double, kNumBands> equalisation{};
  for (int b = 0; b < kNumBands; ++b) equalisation[size_t(b)] = 1.0 / kappa_[size_t(b)];
  levelWeight_ = viewWeights(filters, channelWeight_, equalisation, masks, fft, sampleRate_);
  setOmniGains();
}

void SpatialIrSynthesizer::setOmniGains() {
  omniGains_.assign(channels_, 0.f);
  if (reference_ == Reference::kChannelAverage) omniGains_.assign(channels_, 1.f);
  if (reference_ == Reference::kFirstChannelPressure) omniGains_[0] = 1.f;
  if (reference_ != Reference::kChannelSum) return;
  std::vector<size_t> used;
  for (size_t c = 0; c < channels_; ++c)
    for (const auto& perChannel : channelWeight_)
      if (perChannel[c].max() > 0.f) {
        used.push_back(c);
        break;
      }
  for (size_t c : used) omniGains_[c] = float(1.0 / std::sqrt(double(used.size())));
}

void SpatialIrSynthesizer::directionBands(size_t d, const std::vector<float>& sequence,
                                          const DirectionFilter& filter,
                                          const OctaveBandMasks& masks, FftwRealTransforms& fft) {
  const size_t nbins = fft.n / 2 + 1;
  const float scale = 1.f / float(fft.n);
  Spectrum seqSpec(nbins), channelSpec(nbins);
  spectrumOf(fft, sequence, seqSpec);  // also leaves it in fft.spec
  envelopes_.push_back(BandEnvelope(sampleRate_, sequence, length_, filterData_,
                                    measureLowBands(fft, masks, length_)));
  // One-tap filters are gains: one unit-filter band signal per direction, scaled per channel
  // when accumulated (K x 8 x length floats instead of K x N x 8 x length).
  static const DirectionFilter kUnit{{{1.f}}};
  const DirectionFilter& stored = gainsOnly_ ? kUnit : filter;
  (*bands_)[d].resize(stored.channels.size());
  gains_[d].resize(channels_);
  for (size_t c = 0; c < channels_; ++c) gains_[d][c] = gainsOnly_ ? filter.channels[c][0] : 1.f;
  for (size_t c = 0; c < stored.channels.size(); ++c) {
    spectrumOf(fft, stored.channels[c], channelSpec);
    for (int b = 0; b < kNumBands; ++b) {
      const float eq = float(std::sqrt(1.0 / kappa_[size_t(b)]));
      for (size_t k = 0; k < nbins; ++k) {
        const float g = masks.gain(b, k) * masks.gain(b, k) * scale * eq;
        const std::complex<float> v = g * seqSpec[k] * channelSpec[k];
        fft.band.p[k][0] = v.real();
        fft.band.p[k][1] = v.imag();
      }
      fftwf_execute_dft_c2r(fft.inv, fft.band.p, fft.time.p);
      // Advanced by the filters' delay: the envelope's gains then meet the pulses they were
      // set for, and synthesize() delays the rendered field by it again.
      (*bands_)[d][c][size_t(b)].assign(fft.time.p + reverbDelay_,
                                        fft.time.p + reverbDelay_ + length_);
    }
  }
}

void SpatialIrSynthesizer::omniBands(const std::vector<float>& sequence,
                                     const OctaveBandMasks& masks, FftwRealTransforms& fft,
                                     double lengthSeconds) {
  // One more sequence, through A_b only (no channel filter).
  const size_t nbins = fft.n / 2 + 1;
  const float scale = 1.f / float(fft.n);
  Spectrum seqSpec(nbins);
  spectrumOf(fft, sequence, seqSpec);
  std::array<std::vector<float>, BandEnvelope::kRealisedBands> measured;
  for (int b = 0; b < kDirectionalFromBand; ++b) {
    for (int pass = 0; pass < 2; ++pass) {
      for (size_t k = 0; k < nbins; ++k) {
        const float m = masks.gain(b, k);
        const float g = (pass == 0 ? m * m : m * m * m) * scale;
        fft.band.p[k][0] = seqSpec[k].real() * g;
        fft.band.p[k][1] = seqSpec[k].imag() * g;
      }
      fftwf_execute_dft_c2r(fft.inv, fft.band.p, fft.time.p);
      if (pass == 0) {
        (*omniBands_)[size_t(b)].assign(fft.time.p, fft.time.p + length_);
      } else if (b < BandEnvelope::kRealisedBands) {
        measured[size_t(b)].assign(fft.time.p, fft.time.p + length_);
      }
    }
  }
  omniEnvelope_.emplace(sampleRate_, sequence, length_, filterData_, measured);
  omniEnergy_ = EnergyResponse(lengthSeconds, 1e-3);
}

void SpatialIrSynthesizer::sumOmniEnergy(const DirectionalEnergyResponse& energy, size_t count) {
  // Same bins as the directions' responses.
  if (omniEnergy_.binCount() != energy.response(0).binCount())
    omniEnergy_ =
        EnergyResponse(double(energy.response(0).binCount()) * energy.response(0).binSeconds(),
                       energy.response(0).binSeconds());
  omniEnergy_.clear();
  for (size_t d = 0; d < count; ++d)
    for (size_t k = 0; k < omniEnergy_.binCount(); ++k)
      for (int b = 0; b < kDirectionalFromBand; ++b)
        omniEnergy_.bins()[k][b] += energy.response(d).bins()[k][b];
}

void SpatialIrSynthesizer::synthesize(const DirectionalEnergyResponse& energy,
                                      const DirectSound& direct, std::span<float* const> channels,
                                      std::span<const SpecularPath> early, size_t lateField) {
  for (float* out : channels) std::fill(out, out + length_, 0.f);
  const size_t count = std::min(energy.directionCount(), directions_.size());
  const LateRotation rotation = LateRotation::forField(
      lateField, rotationFrom_, length_, BandEnvelope::binSamplesFor(sampleRate_, 0));
  for (size_t d = 0; d < count; ++d) {
    envelopes_[d].rotate(rotation);
    envelopes_[d].compute(energy.response(d));
  }
  sumOmniEnergy(energy, count);
  omniEnvelope_->rotate(rotation);
  omniEnvelope_->compute(omniEnergy_);
  const size_t onset = firstArrivalSample(energy, direct, early);
  if (coherence_) setEarMix(energy, count, onset);
  std::array<const float*, kNumBands> omni{};
  for (int b = 0; b < kDirectionalFromBand; ++b) omni[size_t(b)] = (*omniBands_)[size_t(b)].data();
  omniEnvelope_->startAt(onset, omni);
  for (size_t d = 0; d < count; ++d) envelopes_[d].startAt(onset, bandSignals(d, 0));
  // Cache-blocked: each output block stays in L1 while all K x N x 8 band signals stream
  // through it once (the loop is memory-bound: the band signals are K x 8 N x length floats).
  constexpr size_t kBlock = 2048;
  for (size_t begin = onset; begin < length_; begin += kBlock) {
    const size_t end = std::min(length_, begin + kBlock);
    accumulateDirections(count, channels, begin, end);
    for (size_t c = 0; c < channels_; ++c)
      if (omniGains_[c] != 0.f)
        omniEnvelope_->accumulateRange(omni, channels[c], begin, end, omniGains_[c], 0,
                                       kDirectionalFromBand);
  }
  placeArrivals(energy, direct, early);
  if (channelLevelling_) {
    // The reverberant part is levelled before the filters' delay moves it; the arrivals, which
    // carry that delay in their filters, are seen reverbDelay_ samples earlier to line up.
    for (size_t c = 0; c < channels_; ++c) fixedFrom_[c] = fixed_[c].data() + reverbDelay_;
    const bool placed = !arrivalDelays_.empty();  // none: no fixed part to transform
    channelLevelling_->level(energy, count, levelWeight_, omniGains_, kDirectionalFromBand, onset,
                             channels, placed ? std::span<const float* const>(fixedFrom_)
                                              : std::span<const float* const>());
  }
  delayFrom(onset, reverbDelay_, length_, channels);  // as the filters delay every arrival
  if (!arrivalDelays_.empty())
    for (size_t c = 0; c < channels_; ++c)
      for (size_t t = 0; t < length_; ++t) channels[c][t] += fixed_[c][t];
  level(energy, count, channels);
  cutLeadingResidue(channels, length_, onset, sampleRate_);
}

void SpatialIrSynthesizer::accumulateDirections(size_t count, std::span<float* const> channels,
                                                size_t begin, size_t end) {
  if (coherence_) return accumulateMixed(count, channels, begin, end);
  if (!gainsOnly_) {
    for (size_t d = 0; d < count; ++d)
      for (size_t c = 0; c < channels_; ++c)
        envelopes_[d].accumulateRange(bandSignals(d, c), channels[c], begin, end, gains_[d][c],
                                      kDirectionalFromBand, kNumBands);
    return;
  }
  // Gains only (panning, Ambisonics): a direction's enveloped bands are the same signal in
  // every channel, so they are summed once and mixed by the gains (K x (bands + N) passes over
  // the block instead of K x N x bands).
  float* y = directionScratch_.data();
  for (size_t d = 0; d < count; ++d) {
    std::fill(y + begin, y + end, 0.f);
    envelopes_[d].accumulateRange(bandSignals(d, 0), y, begin, end, 1.f, kDirectionalFromBand,
                                  kNumBands);
    for (size_t c = 0; c < channels_; ++c) {
      const float g = gains_[d][c];
      if (g == 0.f) continue;
      float* out = channels[c];
      for (size_t n = begin; n < end; ++n) out[n] += g * y[n];
    }
  }
}

void SpatialIrSynthesizer::setEarMix(const DirectionalEnergyResponse& energy, size_t count,
                                     size_t onset) {
  // Two parts, each matched with its own direction energies: the early part and the late
  // part from ISO 3382-1's 80 ms after the first arrival on, whose coherence listeners hear
  // as the room's envelopment. The mix changes at one sample, as the envelopes' gains do at
  // their bins' edges.
  mixSplit_ = onset + size_t(std::lround(kLateAfterSeconds * sampleRate_));
  const double split = double(mixSplit_) / sampleRate_;
  for (size_t d = 0; d < count; ++d) {
    const EnergyResponse& r = energy.response(d);
    auto& [early, late] = directionTotals_[d];
    early = late = Bands{};
    for (size_t k = 0; k < r.binCount(); ++k)
      ((double(k) + 0.5) * r.binSeconds() < split ? early : late) += r.bins()[k];
  }
  for (int part = 0; part < 2; ++part)
    for (int b = 0; b < kNumBands; ++b) {
      for (size_t d = 0; d < count; ++d) bandEnergy_[d] = double(directionTotals_[d][part][b]);
      earMix_[size_t(part)][size_t(b)] =
          coherence_->mix(b, std::span<const double>(bandEnergy_.data(), count));
    }
}

void SpatialIrSynthesizer::accumulateMixed(size_t count, std::span<float* const> channels,
                                           size_t begin, size_t end) {
  float* ears[2] = {earScratch_[0].data(), earScratch_[1].data()};
  for (int b = kDirectionalFromBand; b < kNumBands; ++b) {
    for (float* e : ears) std::fill(e + begin, e + end, 0.f);
    for (size_t d = 0; d < count; ++d)
      for (size_t c = 0; c < 2; ++c)
        envelopes_[d].accumulateRange(bandSignals(d, c), ears[c], begin, end, gains_[d][c], b,
                                      b + 1);
    const size_t split = std::clamp(mixSplit_, begin, end);
    for (int part = 0; part < 2; ++part) {
      const EarMix& m = earMix_[size_t(part)][size_t(b)];
      for (size_t n = part ? split : begin; n < (part ? end : split); ++n) {
        const float l = ears[0][n], r = ears[1][n];
        channels[0][n] += m.same[0] * l + m.other[0] * r;
        channels[1][n] += m.other[1] * l + m.same[1] * r;
      }
    }
  }
}

std::array<const float*, kNumBands> SpatialIrSynthesizer::bandSignals(size_t d, size_t c) const {
  if (gainsOnly_) c = 0;
  std::array<const float*, kNumBands> bands;
  for (int b = 0; b < kNumBands; ++b) bands[size_t(b)] = (*bands_)[d][c][size_t(b)].data();
  return bands;
}

size_t SpatialIrSynthesizer::firstArrivalSample(const DirectionalEnergyResponse& energy,
                                                const DirectSound& direct,
                                                std::span<const SpecularPath> early) const {
  double t = direct.visible ? double(direct.delaySeconds) : 1e300;
  for (const SpecularPath& p : early) t = std::min(t, p.delaySeconds);
  for (size_t d = 0; d < std::min(energy.directionCount(), directions_.size()); ++d) {
    const EnergyResponse& r = energy.response(d);
    for (size_t k = 0; k < r.binCount() && double(k) * r.binSeconds() < t; ++k)
      if (r.bins()[k].max() > 0.f) {
        t = double(k) * r.binSeconds();
        break;
      }
  }
  return size_t(std::clamp(std::lround(std::min(t, 1e9) * sampleRate_), 0L, long(length_)));
}

void SpatialIrSynthesizer::level(const DirectionalEnergyResponse& energy, size_t count,
                                 std::span<float* const> channels) {
  // Each channel's target: sum_d E_d,b x the channel filter's band energy for direction d
  // (diffuse-field equalised), plus each arrival through its exact filter.
  // Channels are independent: worker g levels channels g, g + W, ... with its own leveller,
  // so the result does not depend on the workers or their order.
  const size_t workers = parallel_ ? levellers_.size() : 1;
  binned_.resize(count);
  for (size_t d = 0; d < count; ++d) levellers_[0]->binResponse(energy.response(d), binned_[d]);
  const auto group = [&](size_t g) {
    BandLeveller& leveller = *levellers_[g];
    for (size_t c = g; c < channels_; c += workers) {
      leveller.clearTargets();
      for (size_t d = 0; d < count; ++d) leveller.addBinned(binned_[d], levelWeight_[d][c]);
      for (size_t i = 0; i < arrivalDelays_.size(); ++i)
        leveller.addDirect(arrivalDelays_[i], arrivalEnergy_[i * channels_ + c]);
      // The bands this channel's windows level are left alone.
      std::array<BandLeveller::Levelling, kNumBands> perBand;
      for (int b = 0; b < kNumBands; ++b)
        perBand[size_t(b)] = {kLevelTolerance, kLevelMaxBoost, b > lastWindowLevelledBandOf(c)};
      leveller.apply(channels[c], perBand);
    }
  };
  if (workers > 1)
    parallel_(workers, group);
  else
    group(0);
}

}  // namespace dpc
