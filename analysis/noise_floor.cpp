#include "analysis/noise_floor.h"

#include <algorithm>
#include <cmath>

namespace dpc::audio {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kFirstIntervalSeconds = 0.020;  // step 1 (Lundeby: 10-50 ms)
constexpr double kTailFraction = 0.1;            // steps 2 and 7: at least the last 10 %
constexpr double kFirstFitAboveNoiseDb = 10.0;   // step 3 (Lundeby: 5-10 dB)
constexpr double kIntervalsPer10Db = 5.0;        // step 5 (Lundeby: 3-10)
constexpr double kNoiseAfterCrossingDb = 10.0;   // step 7 (Lundeby: 5-10 dB)
constexpr double kLateFitAboveNoiseDb = 10.0;    // step 8: lower end (Lundeby: 5-10 dB)
constexpr double kLateFitRangeDb = 20.0;         // step 8: dynamic range (Lundeby: 10-20 dB)
constexpr int kMaxIterations = 5;                // steps 7-9 (Lundeby: "max. 5")
constexpr size_t kMinFitIntervals = 3;           // fewer points fit no line
constexpr size_t kMinIntervals = 10;             // a record shorter than this many intervals
constexpr double kMinExcessDb = 6.0;             // a floor lies this far above the decay's tail
constexpr double kMaxFlatFraction = 0.25;        // and falls at most this fraction as fast,
constexpr double kSignificance = 3.0;            // both by this many standard errors,
constexpr double kFloorSlopeTolerance = 0.05;    // and as a floor would, to this share of the decay

double toDb(double x) {
  return x > 0 ? 10.0 * std::log10(x) : -kInf;
}

// dB = a + b t (t in s), a decay when b < 0, fitted to `count` points at times of mean tMean
// and sum of squared deviations sxx, with residual standard deviation sigma (dB).
struct Line {
  double a = kNaN, b = kNaN;
  double sigma = kNaN, tMean = kNaN, sxx = kNaN;
  size_t count = 0;
  bool decays() const { return std::isfinite(a) && std::isfinite(b) && b < 0; }
  double timeAt(double db) const { return (db - a) / b; }
  double secondsPer10Db() const { return -10.0 / b; }
  double slopeError() const { return sigma / std::sqrt(sxx); }
  // Standard error of the line's level at t (least-squares prediction of the mean).
  double levelError(double t) const {
    return sigma * std::sqrt(1.0 / double(count) + (t - tMean) * (t - tMean) / sxx);
  }
};

// Mean energy per sample over intervals of w samples: interval centres (s) and levels (dB).
struct Envelope {
  std::vector<double> t, db;
};

Envelope smoothed(const std::vector<double>& e, size_t w, double dt) {
  Envelope env;
  for (size_t i = 0; i < e.size(); i += w) {
    const size_t end = std::min(e.size(), i + w);
    double sum = 0;
    for (size_t k = i; k < end; ++k) sum += e[k];
    env.t.push_back((double(i) + 0.5 * double(end - i - 1)) * dt);
    env.db.push_back(toDb(sum / double(end - i)));
  }
  return env;
}

double meanEnergy(const std::vector<double>& e, size_t from) {
  double sum = 0;
  for (size_t k = from; k < e.size(); ++k) sum += e[k];
  return from < e.size() ? sum / double(e.size() - from) : kNaN;
}

// Least-squares line through the envelope's points [first, last), with its statistics.
Line fit(const Envelope& env, size_t first, size_t last) {
  if (last < first + kMinFitIntervals) return {};
  Line line;
  line.count = last - first;
  const double m = double(line.count);
  double sy = 0;
  line.tMean = 0;
  for (size_t i = first; i < last; ++i) line.tMean += env.t[i] / m, sy += env.db[i];
  line.sxx = 0;
  double sxy = 0;
  for (size_t i = first; i < last; ++i) {
    const double dx = env.t[i] - line.tMean;
    line.sxx += dx * dx, sxy += dx * env.db[i];
  }
  if (!(line.sxx > 0)) return {};
  line.b = sxy / line.sxx;
  line.a = sy / m - line.b * line.tMean;
  double residuals = 0;
  for (size_t i = first; i < last; ++i) {
    const double r = env.db[i] - line.a - line.b * env.t[i];
    residuals += r * r;
  }
  line.sigma = std::sqrt(residuals / (m - 2.0));
  return line;
}

// Line through the envelope from its first interval at or below hiDb after the peak to its
// last one at or above loDb before tEnd (s), the intervals between included whatever their
// level: a band's envelope dips (Rayleigh fading) inside the range would otherwise end it early
// (steps 3 and 8).
Line fitBetween(const Envelope& env, double hiDb, double loDb, double tEnd) {
  const size_t size = env.db.size();
  size_t first = size_t(std::max_element(env.db.begin(), env.db.end()) - env.db.begin());
  while (first < size && env.db[first] > hiDb) ++first;
  size_t last = first;
  for (size_t i = first; i < size && env.t[i] < tEnd; ++i)
    if (env.db[i] >= loDb) last = i + 1;
  return fit(env, first, last);
}

// First sample of the noise region (step 7): 10 dB of decay past the crossing tc, but no
// later than the start of the last 10 %.
size_t noiseStart(size_t n, double dt, double tc, const Line& line) {
  const size_t tail = size_t(std::floor((1.0 - kTailFraction) * double(n)));
  const double t = tc + kNoiseAfterCrossingDb / 10.0 * line.secondsPer10Db();
  return t / dt >= double(tail) ? tail : size_t(std::max(0.0, t / dt));
}

// Interval length (samples) for kIntervalsPer10Db per 10 dB of the line's decay (step 5).
size_t intervalFor(const Line& line, size_t n, double dt) {
  const double w = line.secondsPer10Db() / kIntervalsPer10Db / dt;
  return std::clamp<size_t>(size_t(std::llround(std::min(w, 1e12))), 1, n / kMinIntervals);
}

// The current line, its crossing with the noise (s), the interval length and the noise.
struct Estimate {
  Line line;
  double tc = kNaN;
  size_t w = 1;
  double noise = kNaN;
};

// Steps 1-4: the first line, from the peak down to 10 dB above the last 10 %'s noise.
bool preliminary(const std::vector<double>& e, double dt, Estimate& est) {
  const size_t n = e.size();
  const double w = std::min(kFirstIntervalSeconds / dt, 1e12);
  est.w = std::clamp<size_t>(size_t(std::llround(w)), 1, n / kMinIntervals);
  est.noise = meanEnergy(e, size_t(std::floor((1.0 - kTailFraction) * double(n))));
  if (!(est.noise > 0) || !std::isfinite(est.noise)) return false;
  const double noiseDb = toDb(est.noise);
  const double tEnd = (1.0 - kTailFraction) * double(n) * dt;  // before the noise's tail
  est.line = fitBetween(smoothed(e, est.w, dt), kInf, noiseDb + kFirstFitAboveNoiseDb, tEnd);
  est.tc = est.line.timeAt(noiseDb);
  return est.line.decays();
}

// Steps 5 and 7-9 once; false when no late decay can be fitted. `converged` when the crossing
// moved by less than one interval.
bool refine(const std::vector<double>& e, double dt, Estimate& est, bool& converged) {
  const size_t n = e.size();
  est.w = intervalFor(est.line, n, dt);
  const size_t from = noiseStart(n, dt, est.tc, est.line);
  est.noise = meanEnergy(e, from);
  if (!(est.noise > 0) || !std::isfinite(est.noise)) return false;
  const double noiseDb = toDb(est.noise);
  const double lo = noiseDb + kLateFitAboveNoiseDb;
  const Line late = fitBetween(smoothed(e, est.w, dt), lo + kLateFitRangeDb, lo, double(from) * dt);
  if (!late.decays()) return false;
  const double tc = late.timeAt(noiseDb);
  converged = std::abs(tc - est.tc) < double(est.w) * dt;
  est.line = late;
  est.tc = tc;
  return true;
}

// Sum of the line's energy 10^((a + b k dt) / 10) over the samples k in [from, from + m);
// m = infinity sums the whole exponential tail.
double lineSum(const Line& line, double dt, size_t from, double m) {
  const double logRatio = line.b * dt * std::log(10.0) / 10.0;  // < 0: ln of one sample's decay
  const double first = std::pow(10.0, (line.a + line.b * double(from) * dt) / 10.0);
  return first * std::expm1(m * logRatio) / std::expm1(logRatio);
}

// Whether the line `tail` falls significantly (kSignificance standard errors) less than
// kMaxFlatFraction as fast as the decay `decay`.
bool flatterThan(const Line& tail, const Line& decay) {
  const double error = std::hypot(tail.slopeError(), kMaxFlatFraction * decay.slopeError());
  return tail.b - kMaxFlatFraction * decay.b > kSignificance * error;
}

// Least-squares slope (dB/s) over the envelope's points [first, end) of what a stationary floor
// of `floorEnergy` per sample under the line `late` would give there.
double floorModelSlope(const Envelope& env, size_t first, const Line& late, double floorEnergy) {
  Envelope model;
  for (size_t i = first; i < env.t.size(); ++i) {
    model.t.push_back(env.t[i]);
    model.db.push_back(toDb(floorEnergy + std::pow(10.0, (late.a + late.b * env.t[i]) / 10.0)));
  }
  return fit(model, 0, model.t.size()).b;
}

// The verdict (see the header): over the noise region [from, n) the mean lies kMinExcessDb
// above the late line's extrapolation; the envelope falls at most kMaxFlatFraction as fast
// as the late line or (more points, so a smaller error in a low band) the whole decay from the
// peak down to the late line's lower end; each by kSignificance standard errors of the lines
// (the envelope's scatter about them: large in a low band's short tail, where the decision is
// then left to the 90 % rule). And the envelope's slope is the one a stationary floor plus the
// late line would give, within kSignificance standard errors or kFloorSlopeTolerance of the
// decay's slope: a second, slower decay (coupled rooms, a ringing mode) is not flat.
// `noise` is the region's mean energy, `env` the envelope at the estimate's interval length.
bool isFloor(size_t n, double dt, const Estimate& est, size_t from, double noise,
             const Envelope& env, double& excessDb) {
  const Line& late = est.line;
  const double noiseDb = toDb(noise);
  const double lineMean = lineSum(late, dt, from, double(n - from)) / double(n - from);
  excessDb = noiseDb - toDb(lineMean);
  const size_t first =
      size_t(std::lower_bound(env.t.begin(), env.t.end(), double(from) * dt) - env.t.begin());
  const Line tail = fit(env, first, env.t.size());
  if (tail.count < kMinFitIntervals) return false;
  // The line's energy over the region lies mostly near its start: judge the level there.
  const double levelError =
      std::hypot(late.levelError(double(from) * dt), tail.sigma / std::sqrt(double(tail.count)));
  if (!(excessDb >= std::max(kMinExcessDb, kSignificance * levelError))) return false;
  const Line whole = fitBetween(env, kInf, noiseDb + kLateFitAboveNoiseDb, double(from) * dt);
  if (!flatterThan(tail, late) && !(whole.decays() && flatterThan(tail, whole))) return false;
  const double model = floorModelSlope(env, first, late, noise - lineMean);
  const double allowed =
      std::max(kSignificance * tail.slopeError(), kFloorSlopeTolerance * -late.b);
  return std::abs(tail.b - model) <= allowed;
}

// Fills `out` from the final estimate: the verdict and, for a floor, the crossing, the noise
// and the correction.
void judge(const std::vector<double>& e, double dt, const Estimate& est, NoiseFloor& out) {
  const size_t n = e.size(), from = noiseStart(n, dt, est.tc, est.line);
  if (!(est.tc > 0) || !(est.tc / dt < double(from))) return;
  const double noise = meanEnergy(e, from);
  const Envelope env = smoothed(e, est.w, dt);
  if (!isFloor(n, dt, est, from, noise, env, out.excessDb)) return;
  out.found = true;
  out.crossing = std::max<size_t>(1, size_t(std::ceil(est.tc / dt)));
  out.noise = noise;
  out.decayDbPerSecond = est.line.b;
  out.tailEnergy = lineSum(est.line, dt, out.crossing, kInf);
  out.peakAboveNoiseDb = *std::max_element(env.db.begin(), env.db.end()) - toDb(out.noise);
}

}  // namespace

NoiseFloor findNoiseFloor(const std::vector<double>& e, double dt) {
  NoiseFloor out;
  if (!(dt > 0) || !std::isfinite(dt) || e.size() < 2 * kMinIntervals) return out;
  Estimate est;
  if (!preliminary(e, dt, est)) return out;
  bool converged = false;
  for (int i = 0; i < kMaxIterations && !converged; ++i)
    if (!refine(e, dt, est, converged)) return out;
  judge(e, dt, est, out);
  return out;
}

}  // namespace dpc::audio
