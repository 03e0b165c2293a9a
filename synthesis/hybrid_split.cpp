#include "synthesis/hybrid_split.h"

#include <algorithm>

namespace dpc {

double HybridSplit::earlyWeight(double t) const {
  const double fadeStart = splitSeconds - fadeSeconds;
  if (t < fadeStart) return 1.0;
  if (t >= splitSeconds || fadeSeconds <= 0.0) return 0.0;
  return (splitSeconds - t) / fadeSeconds;
}

double hybridEarlyLength(double boundsDiagonalMetres, double speedOfSound, double irLength,
                         double fadeSeconds) {
  const double early = boundsDiagonalMetres / speedOfSound + kHybridEarlySeconds + fadeSeconds;
  return std::min(irLength, early);
}

namespace {

void scaleEarly(EnergyResponse& r, const HybridSplit& split) {
  std::vector<Bands>& bins = r.bins();
  for (size_t k = 0; k < bins.size(); ++k) {
    const double w = split.earlyWeight(double(k) * r.binSeconds());
    if (w < 1.0) bins[k] *= float(w);
  }
}

/// late += r's bins times (1 - w); returns the energy added.
double accumulateLate(const EnergyResponse& r, const HybridSplit& split, EnergyResponse& late) {
  const std::vector<Bands>& in = r.bins();
  std::vector<Bands>& out = late.bins();
  const size_t n = std::min(in.size(), out.size());
  double energy = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double w = 1.0 - split.earlyWeight(double(k) * r.binSeconds());
    if (w <= 0.0) continue;
    const Bands part = in[k] * float(w);
    out[k] += part;
    energy += double(part.sum());
  }
  return energy;
}

/// Calls add(delay, intensity, direction) for each exact arrival after the early part.
template <typename Add>
void lateArrivals(const DirectSound& direct, std::span<const SpecularPath> early,
                  const HybridSplit& split, LateShare& share, Add add) {
  if (split.directIsLate(direct)) {
    add(direct.delaySeconds, direct.intensity, direct.direction);
    share.directIsLate = true;
    ++share.lateArrivals;
    share.energy += double(direct.intensity.sum());
  }
  for (const SpecularPath& p : early) {
    if (split.arrivalIsEarly(p.delaySeconds)) continue;
    add(p.delaySeconds, p.intensity, p.direction);
    ++share.lateArrivals;
    share.energy += double(p.intensity.sum());
  }
}

}  // namespace

void keepEarly(EnergyResponse& r, const HybridSplit& split) { scaleEarly(r, split); }

void keepEarly(DirectionalEnergyResponse& r, const HybridSplit& split) {
  for (size_t k = 0; k < r.directionCount(); ++k) scaleEarly(r.response(k), split);
}

LateShare addLate(const EnergyResponse& r, const DirectSound& direct,
                  std::span<const SpecularPath> early, const HybridSplit& split,
                  EnergyResponse& late) {
  LateShare share;
  share.energy = accumulateLate(r, split, late);
  lateArrivals(direct, early, split, share,
               [&](double t, const Bands& i, const glm::vec3&) { late.add(t, i); });
  return share;
}

LateShare addLate(const DirectionalEnergyResponse& r, const DirectSound& direct,
                  std::span<const SpecularPath> early, const HybridSplit& split,
                  DirectionalEnergyResponse& late) {
  LateShare share;
  for (size_t k = 0; k < r.directionCount(); ++k)
    share.energy += accumulateLate(r.response(k), split, late.response(k));
  lateArrivals(direct, early, split, share,
               [&](double t, const Bands& i, const glm::vec3& d) { late.add(t, i, d); });
  return share;
}

void earlyPaths(std::span<const SpecularPath> all, const HybridSplit& split,
                std::vector<SpecularPath>& out) {
  out.clear();
  for (const SpecularPath& p : all)
    if (split.arrivalIsEarly(p.delaySeconds)) out.push_back(p);
}

}  // namespace dpc
