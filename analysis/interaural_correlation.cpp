#include "analysis/interaural_correlation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "common/octave_filter.h"

namespace dpc::audio {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Onset: the first sample within this many dB of the peak (as analysis/room_parameters.cpp).
constexpr double kOnsetBelowPeakDb = 20.0;

/// Both ears' first sample within kOnsetBelowPeakDb of the larger squared peak; n when the
/// ears hold no finite energy.
size_t binauralOnset(const std::vector<double>& l, const std::vector<double>& r) {
  double peak = 0.0;
  for (size_t i = 0; i < l.size(); ++i) peak = std::max({peak, l[i] * l[i], r[i] * r[i]});
  if (!(peak > 0.0) || !std::isfinite(peak)) return l.size();
  const double threshold = peak * std::pow(10.0, -kOnsetBelowPeakDb / 10.0);
  size_t i = 0;
  while (l[i] * l[i] < threshold && r[i] * r[i] < threshold) ++i;
  return i;
}

/// max |IACF(tau)| over |tau| <= maxLag samples, the sums over t in [begin, end); pR(t + tau)
/// outside the record counts as 0. NaN when either ear's window holds no energy.
double iacc(const std::vector<double>& l, const std::vector<double>& r, size_t begin, size_t end,
            long maxLag) {
  double el = 0.0, er = 0.0;
  for (size_t t = begin; t < end; ++t) el += l[t] * l[t], er += r[t] * r[t];
  if (!(el > 0.0) || !(er > 0.0)) return kNaN;
  double best = 0.0;
  const long n = long(r.size());
  for (long lag = -maxLag; lag <= maxLag; ++lag) {
    double sum = 0.0;
    const long lo = std::max(long(begin), -lag), hi = std::min(long(end), n - lag);
    for (long t = lo; t < hi; ++t) sum += l[size_t(t)] * r[size_t(t + lag)];
    best = std::max(best, std::abs(sum));
  }
  return std::min(1.0, best / std::sqrt(el * er));
}

InterauralCorrelation windows(const std::vector<double>& l, const std::vector<double>& r,
                              size_t onset, double fs) {
  const long maxLag = std::lround(kMaxInterauralLagSeconds * fs);
  const size_t split = std::min(l.size(), onset + size_t(std::lround(kInterauralEarlySeconds * fs)));
  return {iacc(l, r, onset, split, maxLag), iacc(l, r, split, l.size(), maxLag),
          iacc(l, r, onset, l.size(), maxLag)};
}

std::vector<double> octaveBand(const std::vector<double>& p, int b, double fs) {
  std::vector<double> band(p.size());
  OctaveBandPass::State state{};
  OctaveBandPass::design(bandCentreExactHz(b), fs).run(p.data(), band.data(), p.size(), state);
  return band;
}

}  // namespace

BinauralAnalysis analyzeBinaural(const float* left, const float* right, size_t n,
                                 int sampleRate) {
  BinauralAnalysis out;
  const InterauralCorrelation none{kNaN, kNaN, kNaN};
  out.bands.fill(none);
  out.broadband = none;
  out.onsetSeconds = kNaN;
  if (!left || !right || n == 0 || sampleRate <= 0) return out;
  const std::vector<double> l(left, left + n), r(right, right + n);
  const size_t onset = binauralOnset(l, r);
  if (onset == n) return out;
  const double fs = double(sampleRate);
  out.onsetSeconds = double(onset) / fs;
  out.broadband = windows(l, r, onset, fs);
  for (int b = 0; b < kNumBands; ++b) {
    if (bandCentreExactHz(b) * std::numbers::sqrt2 >= fs / 2) continue;
    out.bands[size_t(b)] = windows(octaveBand(l, b, fs), octaveBand(r, b, fs), onset, fs);
  }
  return out;
}

}  // namespace dpc::audio
