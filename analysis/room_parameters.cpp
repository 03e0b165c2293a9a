#include "analysis/room_parameters.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <vector>

#include "analysis/noise_floor.h"
#include "common/octave_filter.h"

namespace dpc::audio {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// ISO 3382-1: the evaluation range must end at least this far above the noise/truncation floor.
constexpr double kFloorHeadroomDb = 10.0;
// Without a noise floor found, the floor is read from the decay curve at this fraction of the
// record after the onset.
constexpr double kFloorFraction = 0.9;
// A decay that rises less than this above a noise floor found gives no parameter but its energy
// (ISO 3382-1 asks 10 dB above the range's end; EDT's range needs 20 dB).
constexpr double kMinPeakAboveNoiseDb = 20.0;
// Onset: first sample within this many dB of the peak (ISO 3382-1:2009 A.3.4).
constexpr double kOnsetBelowPeakDb = 20.0;

RoomParameters allNaN() {
  return {kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
}

// Sample times of an energy sequence from the onset: e[0] covers [0, first), e[k >= 1] covers
// [first + (k - 1) dt, first + k dt). first == dt for a sequence whose onset is a bin start.
struct Steps {
  double first, dt;
  double start(size_t k) const { return k == 0 ? 0.0 : first + double(k - 1) * dt; }
  double width(size_t k) const { return k == 0 ? first : dt; }
};

// Least-squares decay time over the points of `levelDb` (sampled at the starts of `steps`)
// lying in [loDb, hiDb]; NaN if the range is not reached, too close to the floor, or too short.
double decayTime(const std::vector<double>& levelDb, const Steps& steps, double hiDb, double loDb,
                 double floorDb) {
  if (loDb < floorDb + kFloorHeadroomDb) return kNaN;
  if (levelDb.empty() || !(levelDb.back() <= loDb)) return kNaN;  // never reaches loDb
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  size_t count = 0;
  for (size_t k = 0; k < levelDb.size(); ++k) {
    const double l = levelDb[k];
    if (l > hiDb) continue;
    if (l < loDb) break;  // the curve is non-increasing
    const double x = steps.start(k);
    sx += x;
    sy += l;
    sxx += x * x;
    sxy += x * l;
    ++count;
  }
  if (count < kMinRegressionPoints) return kNaN;
  const double cnt = double(count);
  const double denom = cnt * sxx - sx * sx;
  if (!(denom > 0)) return kNaN;
  const double slope = (cnt * sxy - sx * sy) / denom;  // dB per second
  if (!(slope < 0)) return kNaN;
  return -60.0 / slope;
}

// Energy in [t0, t0 + window): whole bins plus the straddling bin's share in proportion to time.
double earlyEnergy(const std::vector<double>& e, const Steps& steps, double window) {
  double sum = 0;
  for (size_t k = 0; k < e.size(); ++k) {
    const double start = steps.start(k), width = steps.width(k);
    // Guard against a window landing a hair below a bin boundary.
    const double share = (window - start) / width;
    if (share >= 1.0 - 1e-9) {
      sum += e[k];
      continue;
    }
    if (share > 1e-9) sum += share * e[k];
    break;
  }
  return sum;
}

// Schroeder decay curve (dB re its start) of e[0, n) with `beyond` added to every backward
// sum (the noise compensation's correction; 0 without). `total` is the curve's 0 dB energy.
std::vector<double> schroederDb(const std::vector<double>& e, size_t n, double beyond,
                                double& total) {
  std::vector<double> tail(n);  // tail[k] = beyond + Σ_{k<=j<n} e[j]
  double acc = beyond;
  for (size_t k = n; k-- > 0;) {
    acc += e[k];
    tail[k] = acc;
  }
  total = n > 0 ? tail[0] : 0.0;
  if (!(total > 0) || !std::isfinite(total)) return {};
  std::vector<double> levelDb(n);
  for (size_t k = 0; k < n; ++k)
    levelDb[k] = tail[k] > 0 ? 10.0 * std::log10(tail[k] / total) : -kInf;
  // Monotonic by construction up to rounding; enforce it so the range selection is contiguous.
  for (size_t k = 1; k < n; ++k) levelDb[k] = std::min(levelDb[k], levelDb[k - 1]);
  return levelDb;
}

// All parameters from an energy sequence starting at the onset (e[0] = energy at t0), its
// bins' times `steps`. With a noise floor found, the sequence ends at its crossing and the
// floor's correction is added (ISO 3382-1:2009 5.3.3), and the ranges keep their headroom from
// the curve's level at the crossing; without, from its level at kFloorFraction of the record.
RoomParameters fromEnergy(const std::vector<double>& e, const Steps& steps,
                          const NoiseFloor& noise = {}) {
  RoomParameters r = allNaN();
  const size_t n = noise.found ? std::min(noise.crossing, e.size()) : e.size();
  double total = 0;
  const std::vector<double> levelDb = schroederDb(e, n, noise.found ? noise.tailEnergy : 0, total);
  if (levelDb.empty()) return r;
  r.energy = total;
  if (noise.found) {
    r.inrDb = noise.peakAboveNoiseDb;
    r.truncationSeconds = steps.start(n - 1) + steps.width(n - 1);
  }
  if (noise.found && !(noise.peakAboveNoiseDb >= kMinPeakAboveNoiseDb)) return r;
  const double floorDb = noise.found ? 10.0 * std::log10(noise.tailEnergy / total)
                                     : levelDb[std::min(n - 1, size_t(kFloorFraction * double(n)))];
  r.t20 = decayTime(levelDb, steps, -5.0, -25.0, floorDb);
  r.t30 = decayTime(levelDb, steps, -5.0, -35.0, floorDb);
  r.edt = decayTime(levelDb, steps, 0.0, -10.0, floorDb);

  // A record that ends (or meets its noise) at or before the split holds no late part to
  // compare: C and D are unknown (NaN), not +inf (which says that nothing arrived after it).
  const double recordEnd = steps.start(n - 1) + steps.width(n - 1);
  const auto holdsLate = [&](double window) { return recordEnd > window + 1e-9; };
  auto clarity = [&](double window) {
    if (!holdsLate(window)) return kNaN;
    const double early = earlyEnergy(e, steps, window);
    const double late = std::max(0.0, total - early);
    if (late <= 0) return kInf;
    if (early <= 0) return -kInf;
    return 10.0 * std::log10(early / late);
  };
  r.c50 = clarity(0.050);
  r.c80 = clarity(0.080);
  if (holdsLate(0.050)) r.d50 = std::clamp(earlyEnergy(e, steps, 0.050) / total, 0.0, 1.0);
  return r;
}

std::vector<double> squaredFrom(const std::vector<double>& p, size_t onset) {
  std::vector<double> e(p.size() - onset);
  for (size_t k = onset; k < p.size(); ++k) e[k - onset] = p[k] * p[k];
  return e;
}

}  // namespace

RoomParameters analyzeEnergyDecay(const double* energy, size_t n, double binSeconds,
                                  double onsetSeconds) {
  if (!energy || n == 0 || !(binSeconds > 0)) return allNaN();
  size_t onset = 0;
  while (onset < n && !(energy[onset] > 0)) ++onset;
  if (onset == n) return allNaN();
  std::vector<double> e(n - onset);
  for (size_t k = onset; k < n; ++k) e[k - onset] = energy[k] > 0 ? energy[k] : 0.0;
  // t0 inside the onset bin: that bin covers [t0, its end) only.
  const double end = double(onset + 1) * binSeconds;
  const bool inside = onsetSeconds >= double(onset) * binSeconds && onsetSeconds < end;
  return fromEnergy(e, Steps{inside ? end - onsetSeconds : binSeconds, binSeconds});
}

namespace {

// The IR in double precision and its broadband onset (first sample within kOnsetBelowPeakDb of
// the squared peak); false when the IR holds no finite energy.
bool onsetOf(const float* ir, size_t n, std::vector<double>& p, size_t& onset) {
  if (!ir || n == 0) return false;
  p.assign(ir, ir + n);
  double peak = 0;
  for (double v : p) peak = std::max(peak, v * v);
  if (!(peak > 0) || !std::isfinite(peak)) return false;
  const double threshold = peak * std::pow(10.0, -kOnsetBelowPeakDb / 10.0);
  onset = 0;
  while (p[onset] * p[onset] < threshold) ++onset;
  return true;
}

// p through band b's analysis filter, scaled by 1 / sqrt(analysisFilterImpulseEnergy): false
// (band untouched) when the band's upper edge is at or above Nyquist.
bool bandSignal(const std::vector<double>& p, int b, double fs, std::vector<double>& band) {
  const double fc = bandCentreExactHz(b);
  if (fc * std::numbers::sqrt2 >= fs / 2) return false;
  band.resize(p.size());
  OctaveBandPass::State state{};
  OctaveBandPass::design(fc, fs).run(p.data(), band.data(), p.size(), state);
  const double scale = 1.0 / std::sqrt(analysisFilterImpulseEnergy(b, fs));
  for (double& x : band) x *= scale;
  return true;
}

}  // namespace

double analysisFilterImpulseEnergy(int b, double sampleRate) {
  const double fc = bandCentreExactHz(b);
  if (!(sampleRate > 0.0) || fc * std::numbers::sqrt2 >= sampleRate / 2) return kNaN;
  return OctaveBandPass::design(fc, sampleRate).impulseEnergy(size_t(sampleRate));
}

ImpulseResponseAnalysis analyzeImpulseResponse(const float* ir, size_t n, int sampleRate) {
  ImpulseResponseAnalysis out;
  out.broadband = allNaN();
  out.bands.fill(allNaN());
  std::vector<double> p, band;
  size_t onset = 0;
  if (sampleRate <= 0 || !onsetOf(ir, n, p, onset)) return out;
  const double fs = double(sampleRate);
  const double dt = 1.0 / fs;
  // Per-sample energy from the onset, with Lundeby's noise compensation where a floor is found.
  const auto analyse = [dt](const std::vector<double>& e) {
    return fromEnergy(e, Steps{dt, dt}, findNoiseFloor(e, dt));
  };
  out.broadband = analyse(squaredFrom(p, onset));
  for (int b = 0; b < kNumBands; ++b)
    if (bandSignal(p, b, fs, band)) out.bands[size_t(b)] = analyse(squaredFrom(band, onset));
  return out;
}

BandEnergyBins bandEnergyBins(const float* ir, size_t n, int sampleRate, double binSeconds) {
  BandEnergyBins out{kNaN, kNaN, {}};
  if (sampleRate <= 0 || !(binSeconds > 0) || !std::isfinite(binSeconds)) return out;
  const double fs = double(sampleRate);
  const size_t w = std::max<size_t>(1, size_t(std::llround(std::min(binSeconds * fs, 1e12))));
  out.binSeconds = double(w) / fs;
  std::vector<double> p, band;
  size_t onset = 0;
  if (!onsetOf(ir, n, p, onset)) return out;
  out.onsetSeconds = double(onset) / fs;
  for (int b = 0; b < kNumBands; ++b) {
    if (!bandSignal(p, b, fs, band)) continue;
    std::vector<double>& e = out.energy[size_t(b)];
    e.assign((n - onset + w - 1) / w, 0.0);
    for (size_t i = onset; i < n; ++i) e[(i - onset) / w] += band[i] * band[i];
  }
  return out;
}

}  // namespace dpc::audio
