#include "synthesis/analysis_refinement.h"

#include <algorithm>
#include <cmath>

#include "common/wide_vectors.h"

namespace dpc {

namespace {

// The loops below are plain multiply-adds over independent lanes (common/wide_vectors.h).
constexpr size_t kHalfBands = size_t(kNumBands) / 2;
static_assert(kHalfBands == 4, "one Double4 lane per band of a parity");

/// The IR through the kHalfBands cascades (3 biquads each, transposed direct form II,
/// coefficients c[coef][section], one band per lane) side by side, sample by sample.
/// out[n * kHalfBands + lane], samples [0, end).
DPC_WIDE_VECTORS
void filterCascades(const Double4 (&c)[5][3], const float* ir, size_t end, float* out) {
  Double4 s1[3] = {}, s2[3] = {};
  const Double4 tiny = {1e-150, 1e-150, 1e-150, 1e-150}, zero = {};
  for (size_t n = 0; n < end; ++n) {
    const double in0 = double(ir[n]);
    Double4 x = {in0, in0, in0, in0};
    for (size_t k = 0; k < 3; ++k) {
      const Double4 y = c[0][k] * x + s1[k];
      s1[k] = c[1][k] * x - c[3][k] * y + s2[k];
      s2[k] = c[2][k] * x - c[4][k] * y;
      x = y;
    }
    for (size_t b = 0; b < kHalfBands; ++b) out[n * kHalfBands + b] = float(x[b]);
    if (n % 64 == 63)  // flush values far below float range (denormals would follow)
      for (size_t k = 0; k < 3; ++k) {
        s1[k] = (s1[k] < tiny && s1[k] > -tiny) ? zero : s1[k];
        s2[k] = (s2[k] < tiny && s2[k] > -tiny) ? zero : s2[k];
      }
  }
}

/// Over one synthesis bin of `count` samples, with u the filter's zero-state response to the
/// bin's tilted band signal, u = alpha uBand + gamma uHigh: v = y - gOld u + sum_i d_i basis_i
/// (the band's filter output without its own bin's old contribution, with the zero-input
/// response moved from the old state to the new, d = new - old state), accumulating
/// h += sum v u and c += sum v^2 (four interleaved partial sums). y has stride kHalfBands;
/// basis_i is basis[i * w + m].
DPC_WIDE_VECTORS
void binProducts(const float* y, const float* u, const float* uHigh, double alpha, double gamma,
                 const double* basis, size_t w, const double (&d)[6], double gOld, size_t count,
                 double& h, double& c) {
  Double4 h4 = {}, c4 = {};
  size_t m = 0;
  for (; m + 4 <= count; m += 4) {
    Double4 dr = {};
    for (size_t i = 0; i < 6; ++i) {
      const double* p = basis + i * w + m;
      const Double4 bi = {p[0], p[1], p[2], p[3]};
      dr += d[i] * bi;
    }
    const Double4 ub = {double(u[m]), double(u[m + 1]), double(u[m + 2]), double(u[m + 3])};
    const Double4 uh = {double(uHigh[m]), double(uHigh[m + 1]), double(uHigh[m + 2]),
                        double(uHigh[m + 3])};
    const Double4 uu = alpha * ub + gamma * uh;
    const Double4 yy = {double(y[m * kHalfBands]), double(y[(m + 1) * kHalfBands]),
                        double(y[(m + 2) * kHalfBands]), double(y[(m + 3) * kHalfBands])};
    const Double4 v = yy - gOld * uu + dr;
    h4 += v * uu;
    c4 += v * v;
  }
  double hh = (h4[0] + h4[1]) + (h4[2] + h4[3]), cc = (c4[0] + c4[1]) + (c4[2] + c4[3]);
  for (; m < count; ++m) {
    double dr = 0.0;
    for (size_t i = 0; i < 6; ++i) dr += d[i] * basis[i * w + m];
    const double uu = alpha * double(u[m]) + gamma * double(uHigh[m]);
    const double v = double(y[m * kHalfBands]) - gOld * uu + dr;
    hh += v * uu;
    cc += v * v;
  }
  h += hh;
  c += cc;
}

}  // namespace

AnalysisFilterRefinement::AnalysisFilterRefinement(int sampleRate, size_t length,
                                                   const TiltedBands& bands)
    : sampleRate_(sampleRate), length_(length) {
  size_t maxBins = 0;
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    analysed_[bi] = analysableBand(b, sampleRate);
    if (!analysed_[bi]) continue;
    analysis_[bi] = OctaveBandPass::design(bandCentreExactHz(b), sampleRate);
    unitEnergy_[bi] = analysis_[bi].impulseEnergy(size_t(sampleRate));
    const size_t w = BandEnvelope::binSamplesFor(sampleRate, b);
    maxBins = std::max(maxBins, (length_ + w - 1) / w);
    measureBinResponses(b, bands);
    measureTailForm(b);
    measureZeroInput(b);
  }
  filtered_.assign(kHalfBands * length_, 0.f);
  cumulativeWant_.assign(maxBins, 0.0);
}

void AnalysisFilterRefinement::measureBinResponses(int b, const TiltedBands& bands) {
  const size_t bi = size_t(b);
  const size_t w = BandEnvelope::binSamplesFor(sampleRate_, b);
  const size_t nb = (length_ + w - 1) / w;
  binResponse_[bi].assign(length_, 0.f);
  binResponseEnergy_[bi].assign(nb, 0.0);
  binEndState_[bi].assign(nb, State{});
  binResponseHigh_[bi].assign(length_, 0.f);
  binResponseCross_[bi].assign(nb, 0.0);
  binResponseHighEnergy_[bi].assign(nb, 0.0);
  binEndStateHigh_[bi].assign(nb, State{});
  firstGain_[bi].assign(nb, 0.f);  // capacity for the per-frame copy (no allocation then)
  const std::vector<float>& s = bands.band(b);
  const std::vector<float>& sHigh = bands.upperHalf(b);
  for (size_t j = 0; j < nb; ++j) {
    State st{};
    double e = 0.0;
    for (size_t n = j * w; n < std::min(length_, (j + 1) * w); ++n) {
      const double y = analysis_[bi].step(s[n], st);
      binResponse_[bi][n] = float(y);
      e += y * y;
    }
    binResponseEnergy_[bi][j] = e;
    binEndState_[bi][j] = st;
    State sh{};
    double cross = 0.0, high = 0.0;
    for (size_t n = j * w; n < std::min(length_, (j + 1) * w); ++n) {
      const double y = analysis_[bi].step(sHigh[n], sh);
      binResponseHigh_[bi][n] = float(y);
      cross += double(binResponse_[bi][n]) * y;
      high += y * y;
    }
    binResponseCross_[bi][j] = cross;
    binResponseHighEnergy_[bi][j] = high;
    binEndStateHigh_[bi][j] = sh;
  }
}

void AnalysisFilterRefinement::measureTailForm(int b) {
  const size_t bi = size_t(b);
  std::array<std::vector<double>, 6> resp;
  const size_t ring = size_t(sampleRate_);  // 1 s: the 63 Hz filter has decayed by > 200 dB
  for (size_t i = 0; i < 6; ++i) {
    State st{};
    st[i] = 1.0;
    resp[i].resize(ring);
    for (size_t n = 0; n < ring; ++n) {
      resp[i][n] = analysis_[bi].step(0.0, st);
      if (n % 64 == 63) OctaveBandPass::flushTiny(st);
    }
  }
  for (size_t i = 0; i < 6; ++i)
    for (size_t k = 0; k < 6; ++k) {
      double t = 0.0;
      for (size_t n = 0; n < ring; ++n) t += resp[i][n] * resp[k][n];
      tailForm_[bi][i][k] = t;
    }
}

void AnalysisFilterRefinement::measureZeroInput(int b) {
  const size_t bi = size_t(b);
  const size_t w = BandEnvelope::binSamplesFor(sampleRate_, b);
  zeroInput_[bi].assign(6 * w, 0.0);
  for (size_t i = 0; i < 6; ++i) {
    State st{};
    st[i] = 1.0;
    for (size_t m = 0; m < w; ++m) zeroInput_[bi][i * w + m] = analysis_[bi].step(0.0, st);
    transition_[bi][i] = st;
  }
}

double AnalysisFilterRefinement::tail(size_t b, const State& x, const State& z) const {
  const auto& q = tailForm_[b];
  double t = 0.0;
  for (size_t i = 0; i < 6; ++i)
    for (size_t k = 0; k < 6; ++k) t += x[i] * q[i][k] * z[k];
  return t;
}

AnalysisFilterRefinement::State AnalysisFilterRefinement::advance(size_t b, const State& x) const {
  const auto& tr = transition_[b];
  State z{};
  for (size_t i = 0; i < 6; ++i)
    for (size_t k = 0; k < 6; ++k) z[k] += x[i] * tr[i][k];
  OctaveBandPass::flushTiny(z);
  return z;
}

void AnalysisFilterRefinement::zeroInputStates(size_t b, size_t count, size_t w, State& z,
                                               State& zOld) const {
  if (count == w) {
    z = advance(b, z);
    zOld = advance(b, zOld);
  } else {  // a last, shorter bin
    for (size_t n = 0; n < count; ++n) {
      analysis_[b].step(0.0, z);
      analysis_[b].step(0.0, zOld);
    }
  }
}

double AnalysisFilterRefinement::tiltedBin(size_t b, size_t j, double alpha, double gamma,
                                           State& end) const {
  for (size_t i = 0; i < 6; ++i)
    end[i] = alpha * binEndState_[b][j][i] + gamma * binEndStateHigh_[b][j][i];
  return alpha * alpha * binResponseEnergy_[b][j] + 2.0 * alpha * gamma * binResponseCross_[b][j] +
         gamma * gamma * binResponseHighEnergy_[b][j] + tail(b, end, end);
}

void AnalysisFilterRefinement::findRefineEnd(const EnergyResponse& energy,
                                             std::span<const Arrival> arrivals, size_t widestBin) {
  const double samplesPerBin = energy.binSeconds() * sampleRate_;
  std::array<double, kNumBands> total{}, rest{};
  for (size_t k = 0; k < energy.binCount(); ++k)
    for (int b = 0; b < kNumBands; ++b) total[size_t(b)] += std::max(0.f, energy.bins()[k][b]);
  for (const Arrival& a : arrivals)
    for (int b = 0; b < kNumBands; ++b) total[size_t(b)] += std::max(0.f, a.intensity[b]);
  rest = total;
  refineEnd_ = 0;
  for (size_t k = 0; k < energy.binCount(); ++k) {
    bool any = false;
    for (int b = 0; b < kNumBands; ++b) {
      rest[size_t(b)] -= std::max(0.f, energy.bins()[k][b]);
      any = any || rest[size_t(b)] >= kNegligible * total[size_t(b)];
    }
    refineEnd_ = std::min(length_, size_t(double(k + 1) * samplesPerBin) + 1);
    if (!any) break;
  }
  // whole bins of the widest band, which the per-band loops may reach
  refineEnd_ = std::min(length_, (refineEnd_ + widestBin - 1) / widestBin * widestBin + widestBin);
}

void AnalysisFilterRefinement::filterBands(const float* ir, size_t end, int parity) {
  Double4 c[5][3];
  for (size_t lane = 0; lane < kHalfBands; ++lane)
    for (size_t k = 0; k < 3; ++k) {
      const Biquad& q = analysis_[2 * lane + size_t(parity)].sections[k];
      c[0][k][lane] = q.b0;
      c[1][k][lane] = q.b1;
      c[2][k][lane] = q.b2;
      c[3][k][lane] = q.a1;
      c[4][k][lane] = q.a2;
    }
  filterCascades(c, ir, end, filtered_.data());
}

void AnalysisFilterRefinement::refine(const EnergyResponse& energy, std::span<const Arrival> arrivals,
                                      size_t onset, BandEnvelope& envelope,
                                      const TiltedBands& bands, float* ir) {
  onset_ = onset;
  missing_.fill(0.0);
  findRefineEnd(energy, arrivals, envelope.binSamples(0));
  for (int b = 0; b < kNumBands; ++b)
    if (analysed_[size_t(b)])  // bands above Nyquist (8 kHz at 22.05 kHz) are not refined
      std::copy(envelope.gains(b).begin(), envelope.gains(b).end(), firstGain_[size_t(b)].begin());
  for (int pass = 0; pass < 2 * kSweeps; ++pass) {
    // The filter output of the IR of every band this half-sweep updates, as it starts; each
    // band below subtracts its own part, so it sees its neighbours' leakage. Even bands, then
    // odd ones (red-black Gauss-Seidel: a band's nearest neighbours are updated between its
    // steps).
    filterBands(ir, refineEnd_, pass % 2);
    for (int b = pass % 2; b < kNumBands; b += 2)
      if (analysed_[size_t(b)])
        refineBand(energy, arrivals, b, pass / 2 == kSweeps - 1, envelope, bands, ir);
  }
  // On the response's scale (a band value is a spectral density).
  for (int b = 0; b < kNumBands; ++b)
    if (analysed_[size_t(b)]) missing_[size_t(b)] /= unitEnergy_[size_t(b)];
}

size_t AnalysisFilterRefinement::bandTargets(const EnergyResponse& energy,
                                             std::span<const Arrival> arrivals, int b, size_t w,
                                             size_t nb) {
  const double samplesPerBin = energy.binSeconds() * sampleRate_;
  double* want = cumulativeWant_.data();
  std::fill(want, want + nb, 0.0);
  for (size_t k = 0; k < energy.binCount(); ++k) {
    const size_t n = size_t((double(k) + 0.5) * samplesPerBin);
    want[std::min(nb - 1, n / w)] += std::max(0.f, energy.bins()[k][b]) * unitEnergy_[size_t(b)];
  }
  for (const Arrival& a : arrivals) {
    const long n = std::lround(a.delaySeconds * sampleRate_);
    if (n >= 0 && size_t(n) < length_)
      want[size_t(n) / w] += std::max(0.f, a.intensity[b]) * unitEnergy_[size_t(b)];
  }
  // Bins after the remaining target falls below kNegligible of the total keep their first
  // guess: what is left there moves the decay curve above it by < 0.01 dB.
  double total = 0.0;
  for (size_t j = 0; j < nb; ++j) total += want[j];
  double rest = total;
  for (size_t j = 0; j < nb; ++j) {
    rest -= want[j];
    if (rest < kNegligible * total) return j + 1;
  }
  return nb;
}

void AnalysisFilterRefinement::refineBand(const EnergyResponse& energy, std::span<const Arrival> arrivals,
                                          int b, bool lastSweep, BandEnvelope& envelope,
                                          const TiltedBands& bands, float* ir) {
  std::vector<float>& gain = envelope.gains(b);
  const size_t w = envelope.binSamples(b);
  const size_t stop = bandTargets(energy, arrivals, b, w, gain.size());
  // Forward through the bins, in state-space form; within a bin the zero-input response is a
  // sum of the 6 precomputed basis responses. Each bin is charged with its whole output
  // energy, in the bin and in the ringing that follows (the tail energy of the state,
  // x^T Q x), so a pulse at a bin's end counts in full.
  Walk walk;
  for (size_t j = 0; j < stop; ++j) refineBin(b, j, w, gain, bands, walk, ir);
  if (lastSweep) missing_[size_t(b)] = std::max(0.0, walk.wantSoFar - walk.gotSoFar);
}

void AnalysisFilterRefinement::refineBin(int b, size_t j, size_t w, std::vector<float>& gain,
                                         const TiltedBands& bands, Walk& walk, float* ir) {
  const size_t bi = size_t(b);
  const size_t lo = j * w, hi = std::min(length_, (j + 1) * w);
  const double gOld = gain[j];
  walk.wantSoFar += cumulativeWant_[j];
  walk.gotSoFar -= tail(bi, walk.state, walk.state);  // the tail is measured in this bin
  double h = 0.0, c = 0.0, d[6];
  for (size_t i = 0; i < 6; ++i) d[i] = walk.state[i] - walk.old[i];
  const double alpha = bands.alpha(b, j), gamma = bands.gamma(b, j);
  binProducts(filtered_.data() + bi / 2 + lo * kHalfBands, binResponse_[bi].data() + lo,
              binResponseHigh_[bi].data() + lo, alpha, gamma, zeroInput_[bi].data(), w, d, gOld,
              hi - lo, h, c);
  State z = walk.state, zOld = walk.old;
  zeroInputStates(bi, hi - lo, w, z, zOld);
  State end;
  const double a = tiltedBin(bi, j, alpha, gamma, end);
  h += tail(bi, z, end);
  c += tail(bi, z, z) + walk.gotSoFar;
  const double missing = walk.wantSoFar - c;
  double g = 0.0;
  if (a > 0.0 && missing > 0.0)
    g = std::min((-h + std::sqrt(h * h + a * missing)) / a, kGainRange * double(firstGain_[bi][j]));
  walk.gotSoFar = a * g * g + 2.0 * h * g + c;
  for (size_t i = 0; i < 6; ++i) {
    walk.state[i] = z[i] + g * end[i];
    walk.old[i] = zOld[i] + gOld * end[i];
  }
  const float step = float(g) - gain[j];
  const float* s = bands.tilted(b).data();
  if (step != 0.f)
    for (size_t n = std::max(lo, onset_); n < hi; ++n) ir[n] += step * s[n];
  gain[j] = float(g);
}

}  // namespace dpc
