// EnergyResponse: band energy arriving at the listener per time bin.
//
// bins[k][b] = intensity in octave band b that arrives with a delay in [k*binSeconds,
// (k+1)*binSeconds), relative to the source's emitted power, in 1/m^2 (the direct sound at
// distance r contributes 1/(4 pi r^2), before air absorption). It is what the estimators
// (path tracing, the diffuse path cache) produce each frame and what IR synthesis turns
// into pressure.
// Propagation thread. The constructor allocates; add/clear do not. No errors: arrivals at or
// beyond the length are counted in droppedEnergy() (nothing is lost silently).
#pragma once

#include <vector>

#include "engine/bands.h"

namespace dpc {

class EnergyResponse {
 public:
  EnergyResponse() = default;
  /// lengthSeconds > 0, binSeconds > 0.
  EnergyResponse(double lengthSeconds, double binSeconds);

  /// Adds band intensity at a delay in seconds (>= 0).
  void add(double delaySeconds, const Bands& intensity) {
    const double k = delaySeconds * invBin_;
    if (k >= 0.0 && k < double(bins_.size()))
      bins_[size_t(k)] += intensity;
    else
      dropped_ += intensity;
  }
  void clear();

  double binSeconds() const { return binSeconds_; }
  size_t binCount() const { return bins_.size(); }
  const std::vector<Bands>& bins() const { return bins_; }
  std::vector<Bands>& bins() { return bins_; }
  /// Intensity that arrived too late to be stored since the last clear().
  const Bands& droppedEnergy() const { return dropped_; }
  /// Sum over all bins per band.
  Bands total() const;
  /// The same response in coarser bins of factor * binSeconds (allocates).
  EnergyResponse rebinned(size_t factor) const;

 private:
  double binSeconds_ = 1e-3, invBin_ = 1e3;
  std::vector<Bands> bins_;
  Bands dropped_{0.f};
};

}  // namespace dpc
