#include "synthesis/coherence_match.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include "common/fftw_util.h"
#include "common/bands.h"
#include "common/octave_band_masks.h"
#include "synthesis/spatial_synthesizer.h"

namespace dpc {

namespace {

/// Whether f Hz lies in band b's octave, [fc / sqrt 2, fc sqrt 2).
bool inOctave(int b, double f) {
  const double fc = bandCentreExactHz(b);
  return f >= fc / std::numbers::sqrt2 && f < fc * std::numbers::sqrt2;
}

/// The spectrum of taps (zero-padded to fft.n) on fft.n / 2 + 1 bins.
void spectrumOf(FftwRealTransforms& fft, const std::vector<float>& taps,
                std::vector<std::complex<float>>& out) {
  std::fill(fft.time.p, fft.time.p + fft.n, 0.f);
  std::copy(taps.begin(), taps.begin() + long(std::min(taps.size(), fft.n)), fft.time.p);
  fftwf_execute_dft_r2c(fft.fwd, fft.time.p, fft.spec.p);
  out.resize(fft.n / 2 + 1);
  for (size_t k = 0; k < out.size(); ++k) out[k] = {fft.spec.p[k][0], fft.spec.p[k][1]};
}

/// One HRIR pair's powers per band: over the band's octave (masks null), or weighted by the
/// power of the synthesiser's band filter A_b = M_b^2 (masks: M_b), which is the band signal
/// the mix acts on.
std::array<EarPowers, kNumBands> pairPowers(FftwRealTransforms& fft, const DirectionFilter& f,
                                            int sampleRate, const OctaveBandMasks* masks) {
  if (f.channels.size() != 2)
    throw std::invalid_argument("CoherenceMatch: filters need two channels");
  std::vector<std::complex<float>> l, r;
  spectrumOf(fft, f.channels[0], l);
  spectrumOf(fft, f.channels[1], r);
  std::array<EarPowers, kNumBands> p{};
  for (size_t k = 0; k < l.size(); ++k) {
    const double hz = double(k) * sampleRate / double(fft.n);
    for (int b = 0; b < kNumBands; ++b) {
      const double m2 = masks ? double(masks->gain(b, k)) * masks->gain(b, k) : 1.0;
      const double w = masks ? m2 * m2 : inOctave(b, hz) ? 1.0 : 0.0;
      if (w == 0.0) continue;
      EarPowers& e = p[size_t(b)];
      e.cross += w * double((l[k] * std::conj(r[k])).real());
      e.left += w * double(std::norm(l[k]));
      e.right += w * double(std::norm(r[k]));
    }
  }
  return p;
}

size_t fftSizeFor(const std::vector<DirectionFilter>& filters) {
  size_t longest = 1;
  for (const DirectionFilter& f : filters)
    for (const std::vector<float>& h : f.channels) longest = std::max(longest, h.size());
  return nextPow2(std::max<size_t>(8192, 2 * longest));
}

}  // namespace

double EarPowers::coherence() const {
  return left > 0.0 && right > 0.0 ? cross / std::sqrt(left * right) : 0.0;
}

CoherenceMatch::CoherenceMatch(
    const std::vector<DirectionFilter>& filters,
    const std::function<void(const glm::vec3&, DirectionFilter&)>& exact, int sampleRate,
    int fromBand)
    : fromBand_(fromBand) {
  FftwRealTransforms fft(fftSizeFor(filters));
  const OctaveBandMasks masks(sampleRate, fft.n);
  for (const DirectionFilter& f : filters)
    perDirection_.push_back(pairPowers(fft, f, sampleRate, &masks));
  DirectionFilter scratch;
  for (const glm::vec3& d : uniformSpatialDirections(kDiffuseCoherenceDirections)) {
    exact(d, scratch);
    const std::array<EarPowers, kNumBands> p = pairPowers(fft, scratch, sampleRate, nullptr);
    for (size_t b = 0; b < p.size(); ++b) {
      diffuse_[b].cross += p[b].cross;
      diffuse_[b].left += p[b].left;
      diffuse_[b].right += p[b].right;
    }
  }
}

EarPowers CoherenceMatch::weighted(int b, std::span<const double> energy) const {
  EarPowers sum;
  for (size_t d = 0; d < perDirection_.size() && d < energy.size(); ++d) {
    const EarPowers& p = perDirection_[d][size_t(b)];
    sum.cross += energy[d] * p.cross;
    sum.left += energy[d] * p.left;
    sum.right += energy[d] * p.right;
  }
  return sum;
}

double CoherenceMatch::directions(int b, std::span<const double> energy) const {
  return weighted(b, energy).coherence();
}

EarMix CoherenceMatch::mix(int b, std::span<const double> energy) const {
  constexpr double kLimit = 0.995;
  if (b < fromBand_) return {};
  const EarPowers p = weighted(b, energy);
  const double rho = p.coherence();
  if (!(p.left > 0.0) || !(p.right > 0.0) || !(std::abs(rho) < kLimit)) return {};
  // An ear's power after the mix is P (1 + 2 (a^2 - c^2) (rho_actual - rho)) with
  // a^2 - c^2 = (target - rho) / (2 (1 - rho^2)): where few directions make rho close to 1,
  // the step to the target is held to 1 - rho^2, so that an error e in the predicted
  // coherence changes the power by at most a factor 1 +- e.
  const double step = 1.0 - rho * rho;
  const double target = std::clamp(std::clamp(diffuse(b), rho - step, rho + step), -kLimit, kLimit);
  const double a = std::sqrt((1.0 + target) / (4.0 * (1.0 + rho)));
  const double c = std::sqrt((1.0 - target) / (4.0 * (1.0 - rho)));
  EarMix m;
  m.same = {float(a + c), float(a + c)};
  m.other = {float((a - c) * std::sqrt(p.left / p.right)),
             float((a - c) * std::sqrt(p.right / p.left))};
  return m;
}

}  // namespace dpc
