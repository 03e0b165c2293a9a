#include "engine/energy_response.h"

#include <cmath>
#include <stdexcept>

namespace dpc {

EnergyResponse::EnergyResponse(double lengthSeconds, double binSeconds)
    : binSeconds_(binSeconds), invBin_(1.0 / binSeconds) {
  if (!(lengthSeconds > 0.0) || !(binSeconds > 0.0))
    throw std::invalid_argument("EnergyResponse: length and bin width must be > 0");
  bins_.assign(size_t(std::ceil(lengthSeconds / binSeconds - 1e-9)), Bands(0.f));
}

void EnergyResponse::clear() {
  for (Bands& b : bins_) b = Bands(0.f);
  dropped_ = Bands(0.f);
}

Bands EnergyResponse::total() const {
  Bands s(0.f);
  for (const Bands& b : bins_) s += b;
  return s;
}

EnergyResponse EnergyResponse::rebinned(size_t factor) const {
  EnergyResponse r;
  r.binSeconds_ = binSeconds_ * double(factor);
  r.invBin_ = 1.0 / r.binSeconds_;
  r.bins_.assign((bins_.size() + factor - 1) / factor, Bands(0.f));
  for (size_t k = 0; k < bins_.size(); ++k) r.bins_[k / factor] += bins_[k];
  r.dropped_ = dropped_;
  return r;
}

}  // namespace dpc
