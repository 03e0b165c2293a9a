// The spatial synthesiser's arrivals: the direct sound and the exact early paths, each through
// the exact filter of its listener-frame direction (synthesis/spatial_synthesizer.h), placed
// apart from the reverberant part so that the channel levelling sees them beside it.
#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

#include "common/octave_band_masks.h"
#include "synthesis/filter_shape.h"
#include "synthesis/spatial_synthesizer.h"

namespace dpc {

void SpatialIrSynthesizer::prepareDirect(size_t margin, size_t longestFilter) {
  // Direct-sound convolution: band-shaped impulse (margin) * exact filter, with room for twice
  // the longest direction filter (an exact direction's delay may exceed the K directions').
  fft_ = std::make_shared<FftwRealTransforms>(nextPow2(margin + 2 * longestFilter));
  exactScratch_.channels.assign(channels_, {});
  for (std::vector<float>& h : exactScratch_.channels) h.reserve(margin);
  directWeight_.assign(channels_, Bands{});
  arrivalDelays_.reserve(kReservedArrivals);
  arrivalEnergy_.reserve(kReservedArrivals * channels_);
  const OctaveBandMasks directMasks(sampleRate_, fft_->n);
  directMask2_.resize(fft_->n / 2 + 1);
  for (size_t k = 0; k < directMask2_.size(); ++k)
    for (int b = 0; b < kNumBands; ++b) {
      const bool seen = inAnalysedOctave(b, double(k) * sampleRate_ / double(fft_->n));
      const float m2 = seen ? directMasks.gain(b, k) * directMasks.gain(b, k) : 0.f;
      directMask2_[k][b] = m2;
      directNorm_[size_t(b)] += double(m2);
      std::pair<size_t, size_t>& r = directBins_[size_t(b)];
      if (m2 != 0.f) r = {r.first == r.second ? k : r.first, k + 1};
    }
}

void SpatialIrSynthesizer::directBandWeights(size_t c) {
  Bands& w = directWeight_[c];
  for (int b = 0; b < kNumBands; ++b) {
    double e = 0.0;
    for (size_t k = directBins_[size_t(b)].first; k < directBins_[size_t(b)].second; ++k)
      e += (double(fft_->band.p[k][0]) * fft_->band.p[k][0] +
            double(fft_->band.p[k][1]) * fft_->band.p[k][1]) *
           double(directMask2_[k][b]);
    w[b] = float(e / (directNorm_[size_t(b)] * kappa_[size_t(b)]));
  }
}

void SpatialIrSynthesizer::placeArrivals(const DirectionalEnergyResponse& energy,
                                         const DirectSound& direct,
                                         std::span<const SpecularPath> early) {
  arrivalDelays_.clear();
  arrivalEnergy_.clear();
  if (!direct.visible && early.empty()) return;
  for (size_t c = 0; c < channels_; ++c) {
    std::fill(fixed_[c].begin(), fixed_[c].end(), 0.f);
    fixedTo_[c] = fixed_[c].data();
  }
  if (direct.visible) addArrival(direct, energy.toListener(direct.direction), fixedTo_);
  for (const SpecularPath& p : early) {
    const DirectSound arrival{true, p.length, float(p.delaySeconds), p.intensity, p.direction};
    addArrival(arrival, energy.toListener(p.direction), fixedTo_);
  }
}

void SpatialIrSynthesizer::addArrival(const DirectSound& direct, const glm::vec3& dir,
                                      std::span<float* const> channels) {
  arrivalDelays_.push_back(double(direct.delaySeconds));
  exact_(glm::normalize(dir), exactScratch_);
  const size_t n = fft_->n, nbins = n / 2 + 1, margin = direct_->taps();
  // The band-shaped impulse: sum_b amp_b a_b, diffuse-field equalised, time 0 at centre.
  std::fill(fft_->time.p, fft_->time.p + n, 0.f);
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const float amp = float(std::sqrt(double(direct.intensity[b]) / kappa_[bi]));
    direct_->add(b, amp, 0, fft_->time.p, n);
  }
  const long n0 = std::lround(double(direct.delaySeconds) * sampleRate_) - long(direct_->centre());
  if (oneTap(exactScratch_)) return addGainArrival(direct, n0, channels);
  fftwf_execute_dft_r2c(fft_->fwd, fft_->time.p, fft_->spec.p);
  const float scale = 1.f / float(n);
  for (size_t c = 0; c < channels_; ++c) {
    const std::vector<float>& h = exactScratch_.channels[c];
    std::fill(fft_->time.p, fft_->time.p + n, 0.f);
    const size_t taps = std::min(h.size(), n - margin);  // a longer filter's tail is cut
    std::copy(h.begin(), h.begin() + long(taps), fft_->time.p);
    fftwf_execute_dft_r2c(fft_->fwd, fft_->time.p, fft_->band.p);
    directBandWeights(c);  // the exact filter's band energies, for this channel's target
    Bands e;
    for (int b = 0; b < kNumBands; ++b) e[b] = direct.intensity[b] * directWeight_[c][b];
    arrivalEnergy_.push_back(e);
    for (size_t k = 0; k < nbins; ++k) {
      const float ar = fft_->spec.p[k][0], ai = fft_->spec.p[k][1];
      const float hr = fft_->band.p[k][0], hi = fft_->band.p[k][1];
      fft_->band.p[k][0] = (ar * hr - ai * hi) * scale;
      fft_->band.p[k][1] = (ar * hi + ai * hr) * scale;
    }
    fftwf_execute_dft_c2r(fft_->inv, fft_->band.p, fft_->time.p);
    const size_t used = margin + taps;
    for (size_t i = 0; i < used && i < n; ++i) {
      const long t = n0 + long(i);
      if (t >= 0 && t < long(length_)) channels[c][t] += fft_->time.p[i];
    }
  }
}

bool SpatialIrSynthesizer::oneTap(const DirectionFilter& f) {
  for (const std::vector<float>& h : f.channels)
    if (h.size() != 1) return false;
  return true;
}

void SpatialIrSynthesizer::addGainArrival(const DirectSound& direct, long n0,
                                          std::span<float* const> channels) {
  // Each channel is the band-shaped impulse in fft_->time times its tap g: band energy
  // g^2 x the impulse's, so its weight is g^2 / kappa_b (directBandWeights of a one-tap filter).
  const size_t used = std::min(direct_->taps() + 1, fft_->n);
  for (size_t c = 0; c < channels_; ++c) {
    const float g = exactScratch_.channels[c][0];
    Bands e;
    for (int b = 0; b < kNumBands; ++b) {
      directWeight_[c][b] = float(double(g) * g / kappa_[size_t(b)]);
      e[b] = direct.intensity[b] * directWeight_[c][b];
    }
    arrivalEnergy_.push_back(e);
    for (size_t i = 0; i < used; ++i) {
      const long t = n0 + long(i);
      if (t >= 0 && t < long(length_)) channels[c][t] += g * fft_->time.p[i];
    }
  }
}

}  // namespace dpc
