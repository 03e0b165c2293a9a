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
    if (b < kRealisedBands) {
      const std::vector<float>& m = measured[bi];
      for (size_t n = 0; n < length_ && n < m.size(); ++n)
        sequenceEnergy_[bi][n / binSamples_[bi]] += double(m[n]) * m[n];
    } else {
      for (size_t n = 0; n < length_ && n < sequence.size(); ++n)
        sequenceEnergy_[bi][n / binSamples_[bi]] +=
            double(sequence[n]) * sequence[n] * filters.share[bi];
    }
    target_[bi].assign(nb, 0.0);
    gain_[bi].assign(nb, 0.f);
    wanted_[bi].assign(nb, 0.f);
  }
}

BandEnvelope::BandEnvelope(int sampleRate, const std::vector<float>& sequence, size_t length,
                           const BandFilterData& filters, Realised realised)
    : BandEnvelope(sampleRate, sequence, length, filters,
                   std::array<std::vector<float>, kRealisedBands>{}) {
  // The realised correlations see each band within its analysed octave (measureRealised), so
  // do its targets and the expectation form's e_b[j] (the pulses' energy x that octave's share
  // of beta_b), which tells which bins hold a pulse and gives the first guess of the gains.
  share_ = filters.octaveShare;
  for (int b = 0; b < kNumBands; ++b) {
    std::vector<double>& e = sequenceEnergy_[size_t(b)];
    std::fill(e.begin(), e.end(), 0.0);
    for (size_t n = 0; n < length_ && n < sequence.size(); ++n)
      e[n / binSamples_[size_t(b)]] += double(sequence[n]) * sequence[n] * share_[size_t(b)];
  }
  realised_ = std::move(realised);
  useRealised_ = true;
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
    const size_t onset = useRealised_ ? 0 : moveToNearestPulses(b);
    carryToPulses(b);
    if (!useRealised_) holdGainsOverEmptyBins(b, onset);
  }
}

void BandEnvelope::compute(const EnergyResponse& energy) {
  unplaced_.fill(0.0);
  targets(energy);
  if (useRealised_)
    computeRealised();
  else
    computeExpected();
}

void BandEnvelope::computeRealised() {
  // Gauss-Seidel sweeps over the bands; the coupling between bands is a few per cent, so four
  // sweeps converge far below 0.1 %.
  constexpr int kSweeps = 4;
  for (int b = 0; b < kNumBands; ++b) first_[size_t(b)] = gain_[size_t(b)];
  for (int sweep = 0; sweep < kSweeps; ++sweep)
    for (int b = 0; b < kNumBands; ++b) solveRealisedBand(b, sweep == kSweeps - 1);
}

void BandEnvelope::realisedQuadratic(int b, size_t j, double& a, double& h, double& c) const {
  // Summed over the fine bins q of j, where the upper neighbour's gain may change from one q
  // to the next.
  const size_t bi = size_t(b);
  const auto& fine = realised_.fine[bi];
  const size_t w = binSamples_[bi];
  const size_t fw = b + 1 < kNumBands ? binSamples_[bi + 1] : w;
  const size_t perBin = w / fw;
  const double gLow = b > 0 ? double(gain_[bi - 1][(j * w) / binSamples_[bi - 1]]) : 0.0;
  a = h = c = 0.0;
  const size_t qEnd = std::min(fine.size(), (j + 1) * perBin);
  for (size_t q = j * perBin; q < qEnd; ++q) {
    const double gHigh =
        b + 1 < kNumBands ? double(gain_[bi + 1][(q * fw) / binSamples_[bi + 1]]) : 0.0;
    const Correlations& r = fine[q];
    a += r[3];
    h += gLow * r[1] + gHigh * r[4];
    c += gLow * gLow * r[0] + 2.0 * gLow * gHigh * r[2] + gHigh * gHigh * r[5];
  }
}

void BandEnvelope::solveRealisedBand(int b, bool lastSweep) {
  constexpr double kGainRange = 3.0;
  const size_t bi = size_t(b);
  for (size_t j = 0; j < gain_[bi].size(); ++j) {
    const double want = target_[bi][j];
    if (want <= 0.0) continue;
    double a, h, c;
    realisedQuadratic(b, j, a, h, c);
    if (!(a > 0.0)) continue;  // keep the first guess
    const double disc = h * h - a * (c - want);
    double g = disc > 0.0 ? (-h + std::sqrt(disc)) / a : 0.0;
    // A bin whose pulses sit at its edges has little realised energy inside it; a large gain
    // there would spill into the neighbouring bins through the band filter. Keep the gain
    // within kGainRange of the expectation form's.
    const double guess = first_[bi][j];
    g = std::min(g, kGainRange * guess);
    if (g > 0.0) g = std::max(g, guess / kGainRange);
    if (g > 0.0) {
      gain_[bi][j] = float(g);
    } else {
      gain_[bi][j] = 0.f;
      if (lastSweep) unplaced_[bi] += want;
    }
  }
}

void BandEnvelope::computeExpected() {
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
      for (size_t n = lo; n < hi; ++n) out[n] += g * s[n];
    }
  }
}

void BandEnvelope::startAt(size_t onset, const std::array<const float*, kNumBands>& bands) {
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b), w = binSamples_[bi], j = onset / w;
    if (onset % w == 0 || j >= gain_[bi].size() || gain_[bi][j] == 0.f) continue;
    const float* x = bands[bi];
    double before = 0.0, after = 0.0;
    for (size_t n = j * w; n < onset; ++n) before += double(x[n]) * x[n];
    for (size_t n = onset; n < std::min(length_, (j + 1) * w); ++n) after += double(x[n]) * x[n];
    if (after > 0.0) gain_[bi][j] = float(gain_[bi][j] * std::sqrt((before + after) / after));
  }
}

namespace {

/// y = the sequence (whose spectrum fft.spec holds) through M_b A_nb A_nb within band b's
/// analysed octave (inAnalysedOctave), length samples.
void bandMeasurement(FftwRealTransforms& fft, const OctaveBandMasks& masks, int sampleRate, int b,
                     int nb, size_t length, std::vector<float>& y) {
  const float scale = 1.f / float(fft.n);
  for (size_t k = 0; k < fft.n / 2 + 1; ++k) {
    const bool seen = inAnalysedOctave(b, double(k) * sampleRate / double(fft.n));
    const float g = seen ? masks.gain(b, k) * masks.gain(nb, k) * masks.gain(nb, k) * scale : 0.f;
    fft.band.p[k][0] = fft.spec.p[k][0] * g;
    fft.band.p[k][1] = fft.spec.p[k][1] * g;
  }
  fftwf_execute(fft.inv);
  y.assign(fft.time.p, fft.time.p + length);
}

/// The products of y[0..2] summed over fine bins of fw samples.
void accumulateCorrelations(const std::array<std::vector<float>, 3>& y, size_t length, size_t fw,
                            std::vector<BandEnvelope::Correlations>& fine) {
  fine.assign((length + fw - 1) / fw, BandEnvelope::Correlations{});
  for (size_t n = 0; n < length; ++n) {
    const double lo = y[0][n], mid = y[1][n], hi = y[2][n];
    BandEnvelope::Correlations& r = fine[n / fw];
    r[0] += lo * lo;
    r[1] += lo * mid;
    r[2] += lo * hi;
    r[3] += mid * mid;
    r[4] += mid * hi;
    r[5] += hi * hi;
  }
}

}  // namespace

BandEnvelope::Realised measureRealised(int sampleRate, const std::vector<float>& sequence,
                                       size_t length, FftwRealTransforms& fft,
                                       const OctaveBandMasks& masks) {
  std::fill(fft.time.p, fft.time.p + fft.n, 0.f);
  std::copy(sequence.begin(), sequence.begin() + long(std::min(length, sequence.size())),
            fft.time.p);
  fftwf_execute(fft.fwd);
  BandEnvelope::Realised out;
  std::array<std::vector<float>, 3> y;
  for (int b = 0; b < kNumBands; ++b) {
    for (int i = 0; i < 3; ++i) {
      const int nb = b + i - 1;
      y[size_t(i)].assign(length, 0.f);
      if (nb >= 0 && nb < kNumBands)
        bandMeasurement(fft, masks, sampleRate, b, nb, length, y[size_t(i)]);
    }
    const size_t fw = BandEnvelope::binSamplesFor(sampleRate, std::min(b + 1, kNumBands - 1));
    accumulateCorrelations(y, length, fw, out.fine[size_t(b)]);
  }
  return out;
}

}  // namespace dpc
