#include "synthesis/band_envelope.h"

#include <algorithm>
#include <cmath>

namespace dpc {

namespace {

/// A sequence's bins hold pulses where their energy e_b[j] exceeds this.
bool holdsPulses(double sequenceEnergy) {
  return sequenceEnergy > 1e-12;
}

/// For a walk forward through a band's bins from its onset: the nearer bin holding pulses
/// of a bin without any (the earlier one on a tie, and only a bin at or after the onset), or
/// nb when there is none. `previous` is the walk's last bin holding pulses (nb: none yet).
struct NearestPulseBin {
  const std::vector<double>& sequenceEnergy;
  size_t nb;
  size_t next;  ///< first bin after the last asked one that holds pulses (nb: none), kept
  size_t operator()(size_t j, size_t previous) {
    if (next <= j) {
      next = j + 1;
      while (next < nb && !holdsPulses(sequenceEnergy[next])) ++next;
    }
    const bool back = previous < nb && (next >= nb || j - previous <= next - j);
    return back ? previous : next;
  }
};

}  // namespace

BandEnvelope::BandEnvelope(int sampleRate, const std::vector<float>& sequence, size_t length,
                           const BandFilterData& filters,
                           const std::array<std::vector<float>, kRealisedBands>& measured)
    : sampleRate_(sampleRate), length_(length), coupling_(filters.coupling),
      share_(filters.share) {
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    binSamples_[bi] = binSamplesFor(sampleRate, b);
    const size_t nb = (length_ + binSamples_[bi] - 1) / binSamples_[bi];
    // Expected measured energy of s_b per bin: the pulses' energy in the bin times beta_b
    // (cross terms between pulses have random signs and vanish on average). Using the pulse
    // energy rather than the realised filtered energy keeps the gains of all bands moving
    // together from bin to bin, so neighbouring bands stay coherent in their crossovers.
    sequenceEnergy_[bi].assign(nb, 0.0);
    if (b < kRealisedBands && !measured[bi].empty()) {
      const std::vector<float>& m = measured[bi];
      for (size_t n = 0; n < length_ && n < m.size(); ++n)
        sequenceEnergy_[bi][n / binSamples_[bi]] += double(m[n]) * m[n];
    } else {
      for (size_t n = 0; n < length_ && n < sequence.size(); ++n)
        sequenceEnergy_[bi][n / binSamples_[bi]] +=
            double(sequence[n]) * sequence[n] * filters.share[bi];
    }
    baseEnergy_[bi] = sequenceEnergy_[bi];
    target_[bi].assign(nb, 0.0);
    gain_[bi].assign(nb, 0.f);
    wanted_[bi].assign(nb, 0.f);
  }
}

void BandEnvelope::rotate(const LateRotation& rotation) {
  rotation_ = rotation;
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b), w = binSamples_[bi];
    std::vector<double>& e = sequenceEnergy_[bi];
    for (size_t j = 0; j < e.size(); ++j) e[j] = baseEnergy_[bi][rotation_.source(j * w) / w];
  }
}

size_t BandEnvelope::binSamplesFor(int sampleRate, int b) {
  const size_t base = std::max<size_t>(1, size_t(std::lround(1e-3 * sampleRate)));
  const double want = 2.0 * sampleRate / bandCentreExactHz(b);  // two periods, samples
  size_t w = base;
  while (double(w) < want - 1e-9) w *= 2;
  return w;
}

void BandEnvelope::binTargets(const EnergyResponse& energy, int b) {
  const size_t bi = size_t(b);
  const double samplesPerBin = energy.binSeconds() * sampleRate_;
  auto& target = target_[bi];
  std::fill(target.begin(), target.end(), 0.0);
  const size_t nb = target.size();
  for (size_t k = 0; k < energy.binCount(); ++k) {
    const float e = energy.bins()[k][b];
    if (!(e > 0.f)) continue;  // energy is >= 0: a negative rounding residue counts as 0
    // Assign the energy bin to the synthesis bin holding its centre sample.
    const size_t n = size_t((double(k) + 0.5) * samplesPerBin);
    const size_t j = std::min(nb - 1, n / binSamples_[bi]);
    target[j] += double(e) * share_[bi];
  }
}

size_t BandEnvelope::moveToNearestPulses(int b) {
  // Expectation form (one sequence per direction, sparse early): the energy of a bin the
  // sequence leaves empty goes to the nearer bin that holds pulses, the earlier one only from
  // the band's first bin with energy on (never before the sound's onset), so that the energy's
  // centre in time stays put. Returns that first bin (nb: none).
  auto& target = target_[size_t(b)];
  const auto& seqE = sequenceEnergy_[size_t(b)];
  const size_t nb = target.size();
  size_t onset = nb;
  for (size_t j = 0; j < nb; ++j)
    if (target[j] > 0.0) {
      onset = j;
      break;
    }
  NearestPulseBin nearest{seqE, nb, onset};
  size_t previous = nb;  // last bin at or after the onset holding pulses
  for (size_t j = onset; j < nb; ++j) {
    if (holdsPulses(seqE[j])) {
      previous = j;
      continue;
    }
    if (target[j] == 0.0) continue;
    const size_t to = nearest(j, previous);
    if (to >= nb) continue;  // no bin with pulses after it: carryToPulses leaves it unplaced
    target[to] += target[j];
    target[j] = 0.0;
  }
  return onset;
}

void BandEnvelope::carryToPulses(int b) {
  // Energy of a bin the sequence leaves empty moves on to the next bin; first-guess gains.
  const size_t bi = size_t(b);
  auto& target = target_[bi];
  const auto& seqE = sequenceEnergy_[bi];
  double carry = 0.0;
  for (size_t j = 0; j < target.size(); ++j) {
    const double want = target[j] + carry;
    if (holdsPulses(seqE[j])) {
      target[j] = want;
      gain_[bi][j] = float(std::sqrt(want / seqE[j]));
      carry = 0.0;
    } else {
      target[j] = 0.0;
      gain_[bi][j] = 0.f;
      carry = want;
    }
  }
  unplaced_[bi] += carry;  // after the last bin with pulses: nowhere to go
}

void BandEnvelope::holdGainsOverEmptyBins(int b, size_t onset) {
  // A bin without pulses still carries its neighbours' pulses as the band filter (and a
  // spatial synthesiser's channel filter, with its delay) spreads them; at gain 0 it would cut
  // that part of their energy, which the expected energy e_b[j] counts in the pulse's bin. So
  // from the onset on it takes the gain of the bin it handed its energy to (the nearer bin with
  // pulses, as in moveToNearestPulses), and a sparse sequence's pulses sound whole.
  const size_t bi = size_t(b);
  const auto& seqE = sequenceEnergy_[bi];
  const size_t nb = seqE.size();
  NearestPulseBin nearest{seqE, nb, onset};
  size_t previous = nb;
  for (size_t j = onset; j < nb; ++j) {
    if (holdsPulses(seqE[j])) {
      previous = j;
      continue;
    }
    const size_t from = nearest(j, previous);
    if (from < nb) gain_[bi][j] = gain_[bi][from];
  }
}

void BandEnvelope::targets(const EnergyResponse& energy) {
  for (int b = 0; b < kNumBands; ++b) {
    binTargets(energy, b);
    const size_t onset = moveToNearestPulses(b);
    carryToPulses(b);
    holdGainsOverEmptyBins(b, onset);
  }
}

void BandEnvelope::compute(const EnergyResponse& energy) {
  unplaced_.fill(0.0);
  targets(energy);
  correctCrossovers();
}

void BandEnvelope::correctCrossovers() {
  // Crossover correction: band b's measured energy in a bin is
  // sum_{i,k} g_{b+i} g_{b+k} coupling[b][i][k] times the white energy; scale g_b so that it
  // equals the uncorrected g_b^2 (what the energy response asks for). Gauss-Seidel steps.
  for (int b = 0; b < kNumBands; ++b) wanted_[size_t(b)] = gain_[size_t(b)];
  const BandCoupling& coupling = coupling_;
  for (int iter = 0; iter < 3; ++iter) {
    for (int b = 0; b < kNumBands; ++b) {
      const size_t bi = size_t(b);
      const size_t w = binSamples_[bi];
      for (size_t j = 0; j < gain_[bi].size(); ++j) {
        const double target = wanted_[bi][j];
        if (target == 0.0) continue;
        const size_t centre = std::min(length_ - 1, j * w + w / 2);
        double g[3];
        for (int i = 0; i < 3; ++i) {
          const int nb = b + i - 1;
          g[i] = (nb < 0 || nb >= kNumBands)
                     ? 0.0
                     : double(gain_[size_t(nb)][centre / binSamples_[size_t(nb)]]);
        }
        double measured = 0.0;
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k) measured += g[i] * g[k] * coupling[bi][size_t(i)][size_t(k)];
        if (measured > 0.0) gain_[bi][j] = float(g[1] * std::sqrt(target * target / measured));
      }
    }
  }
}

void BandEnvelope::accumulateRange(const std::array<const float*, kNumBands>& bands, float* out,
                                   size_t begin, size_t end, float scale, int bandBegin,
                                   int bandEnd) const {
  end = std::min(end, length_);
  for (int b = bandBegin; b < bandEnd; ++b) {
    const size_t bi = size_t(b);
    const float* s = bands[bi];
    const size_t w = binSamples_[bi];
    for (size_t j = begin / w; j * w < end; ++j) {
      const float g = gain_[bi][j] * scale;
      if (g == 0.f) continue;
      const size_t lo = std::max(begin, j * w), hi = std::min(end, (j + 1) * w);
      // The bin's samples are contiguous in the band signal too (bin-aligned rotation).
      const float* x = s + rotation_.source(j * w);
      for (size_t n = lo; n < hi; ++n) out[n] += g * x[n - j * w];
    }
  }
}

void BandEnvelope::startAt(size_t onset, const std::array<const float*, kNumBands>& bands) {
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b), w = binSamples_[bi], j = onset / w;
    if (onset % w == 0 || j >= gain_[bi].size() || gain_[bi][j] == 0.f) continue;
    const float* x = bands[bi] + rotation_.source(j * w);  // the bin's samples, as read
    const size_t split = onset - j * w, stop = std::min(length_, (j + 1) * w) - j * w;
    double before = 0.0, after = 0.0;
    for (size_t n = 0; n < split; ++n) before += double(x[n]) * x[n];
    for (size_t n = split; n < stop; ++n) after += double(x[n]) * x[n];
    if (after > 0.0) gain_[bi][j] = float(gain_[bi][j] * std::sqrt((before + after) / after));
  }
}

std::array<std::vector<float>, BandEnvelope::kRealisedBands> measureLowBands(
    FftwRealTransforms& fft, const OctaveBandMasks& masks, size_t length, int bands) {
  std::array<std::vector<float>, BandEnvelope::kRealisedBands> out;
  const float scale = 1.f / float(fft.n);
  for (int b = 0; b < std::min(bands, BandEnvelope::kRealisedBands); ++b) {
    for (size_t k = 0; k < fft.n / 2 + 1; ++k) {
      const float m = masks.gain(b, k);
      fft.band.p[k][0] = fft.spec.p[k][0] * m * m * m * scale;
      fft.band.p[k][1] = fft.spec.p[k][1] * m * m * m * scale;
    }
    fftwf_execute(fft.inv);  // destroys fft.band, which is rebuilt each time
    out[size_t(b)].assign(fft.time.p, fft.time.p + length);
  }
  return out;
}


}  // namespace dpc
