#include "engine/energy_response.h"

#include <cmath>
#include <glm/geometric.hpp>
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

DirectionalEnergyResponse::DirectionalEnergyResponse(double lengthSeconds, double binSeconds,
                                                     std::vector<glm::vec3> directions,
                                                     float exponent)
    : directions_(std::move(directions)), exponent_(exponent) {
  if (directions_.empty() || !(exponent_ > 0.f))
    throw std::invalid_argument("DirectionalEnergyResponse: need directions and exponent > 0");
  for (glm::vec3& d : directions_) d = glm::normalize(d);
  responses_.assign(directions_.size(), EnergyResponse(lengthSeconds, binSeconds));
  weights_.assign(directions_.size(), 0.f);
}

DirectionalEnergyResponse DirectionalEnergyResponse::truncated(double lengthSeconds) const {
  const double bin = responses_.empty() ? 1e-3 : responses_.front().binSeconds();
  DirectionalEnergyResponse r(lengthSeconds, bin, directions_, exponent_);
  r.copyFrame(*this);
  return r;
}

void ListenerFrame::set(const glm::vec3& f, const glm::vec3& u) {
  forward = glm::normalize(f);
  up = glm::normalize(u - forward * glm::dot(u, forward));
  left = glm::cross(up, forward);  // right-handed: left = up x forward
}

glm::vec3 ListenerFrame::toListener(const glm::vec3& w) const {
  return {glm::dot(w, forward), glm::dot(w, left), glm::dot(w, up)};
}

void DirectionalEnergyResponse::add(double delaySeconds, const Bands& intensity,
                                    const glm::vec3& worldDirection) {
  const float len = glm::length(worldDirection);
  if (!(len > 0.f)) {
    // No direction (should not happen): spread evenly.
    for (EnergyResponse& r : responses_) r.add(delaySeconds, intensity / float(responses_.size()));
    return;
  }
  const glm::vec3 d = toListener(worldDirection / len);
  float sum = 0.f;
  for (size_t k = 0; k < directions_.size(); ++k) {
    const float c = std::max(0.f, glm::dot(d, directions_[k]));
    // c^p for p = 4 without pow: the common case.
    const float c2 = c * c;
    weights_[k] = exponent_ == 4.f ? c2 * c2 : std::pow(c, exponent_);
    sum += weights_[k];
  }
  if (!(sum > 0.f)) {
    for (EnergyResponse& r : responses_) r.add(delaySeconds, intensity / float(responses_.size()));
    return;
  }
  const float inv = 1.f / sum;
  for (size_t k = 0; k < directions_.size(); ++k)
    if (weights_[k] > 0.f) responses_[k].add(delaySeconds, intensity * (weights_[k] * inv));
}

void DirectionalEnergyResponse::clear() {
  for (EnergyResponse& r : responses_) r.clear();
}

}  // namespace dpc
