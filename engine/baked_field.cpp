#include "engine/baked_field.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

namespace dpc {

size_t BakedField::bytes() const {
  return (late.size() + directional.size()) * sizeof(float) +
         (probes.size() + sources.size() + axes.size()) * sizeof(glm::vec3);
}

void removeDirect(float* energy, size_t bins, double binSeconds, double delaySeconds,
                  const float* direct) {
  const double k = delaySeconds / binSeconds;
  if (!(k >= 0.0) || k >= double(bins)) return;
  float* row = energy + size_t(k) * kNumBands;
  for (int b = 0; b < kNumBands; ++b) row[b] = std::max(0.f, row[b] - direct[b]);
}

BakeInterpolator::BakeInterpolator(std::shared_ptr<const BakedField> field, const Tracer& tracer,
                                   BakeInterpolation settings)
    : field_(std::move(field)), tracer_(&tracer), settings_(settings) {
  settings_.maxProbes = std::max(1, settings_.maxProbes);
  settings_.candidates = std::max(settings_.maxProbes, settings_.candidates);
  order_.resize(field_->probes.size());
  weights_.reserve(size_t(settings_.maxProbes));
  shares_.resize(field_->axes.size() * kNumBands);
}

bool BakeInterpolator::locate(const glm::vec3& listener) {
  const auto& probes = field_->probes;
  for (size_t p = 0; p < probes.size(); ++p) {
    const glm::vec3 d = probes[p] - listener;
    order_[p] = {glm::dot(d, d), p};
  }
  const size_t n = std::min(order_.size(), size_t(settings_.candidates));
  std::partial_sort(order_.begin(), order_.begin() + std::ptrdiff_t(n), order_.end());
  weights_.clear();
  float sum = 0.f;
  for (size_t i = 0; i < n && weights_.size() < size_t(settings_.maxProbes); ++i) {
    const float dist = std::sqrt(order_[i].first);
    const size_t p = order_[i].second;
    if (dist > kAtProbeMetres) {
      ++rays_;
      TraceRay ray{listener, (probes[p] - listener) / dist, 0.f, dist};
      if (tracer_->occluded(ray)) continue;
    } else if (weights_.empty()) {
      weights_.push_back({p, 1.f});
      sum = 1.f;
      break;
    }
    const float w = 1.f / (dist * dist);
    weights_.push_back({p, w});
    sum += w;
  }
  if (weights_.empty()) {
    ++fallbacks_;
    return false;
  }
  for (ProbeWeight& w : weights_) w.weight /= sum;
  ++located_;
  return true;
}

bool BakeInterpolator::isBaked(size_t source, const glm::vec3& position) const {
  if (source >= field_->sources.size()) return false;
  return glm::length(field_->sources[source] - position) <= kStaticToleranceMetres;
}

const float* BakeInterpolator::lateRow(size_t probe, size_t source) const {
  const BakedField& f = *field_;
  return f.late.data() + (probe * f.sources.size() + source) * f.bins * kNumBands;
}

void BakeInterpolator::response(size_t source, EnergyResponse& out) const {
  out.clear();
  const size_t bins = std::min(out.binCount(), field_->bins);
  auto& dst = out.bins();
  for (const ProbeWeight& w : weights_) {
    const float* row = lateRow(w.probe, source);
    for (size_t k = 0; k < bins; ++k)
      for (int b = 0; b < kNumBands; ++b) dst[k][b] += w.weight * row[k * kNumBands + size_t(b)];
  }
}

void BakeInterpolator::axisShares(size_t source, size_t j, std::vector<float>& shares) const {
  const BakedField& f = *field_;
  const size_t A = f.axes.size(), D = f.directionalBins();
  std::fill(shares.begin(), shares.end(), 0.f);
  for (const ProbeWeight& w : weights_) {
    const float* row =
        f.directional.data() + ((w.probe * f.sources.size() + source) * D + j) * A * kNumBands;
    for (size_t i = 0; i < A * kNumBands; ++i) shares[i] += w.weight * row[i];
  }
  for (int b = 0; b < kNumBands; ++b) {
    float sum = 0.f;
    for (size_t a = 0; a < A; ++a) sum += shares[a * kNumBands + size_t(b)];
    for (size_t a = 0; a < A; ++a)
      shares[a * kNumBands + size_t(b)] = sum > 0.f ? shares[a * kNumBands + size_t(b)] / sum
                                                    : 1.f / float(A);
  }
}

void BakeInterpolator::directional(size_t source, DirectionalEnergyResponse& out) const {
  out.clear();
  const BakedField& f = *field_;
  const size_t A = f.axes.size();
  size_t currentBin = size_t(-1);
  for (size_t k = 0; k < f.bins; ++k) {
    Bands e;
    for (const ProbeWeight& w : weights_)
      for (int b = 0; b < kNumBands; ++b)
        e[b] += w.weight * lateRow(w.probe, source)[k * kNumBands + size_t(b)];
    if (e.v == Bands().v) continue;
    if (k / f.directionalBinFactor != currentBin) {
      currentBin = k / f.directionalBinFactor;
      axisShares(source, currentBin, shares_);
    }
    const double delay = (double(k) + 0.5) * f.binSeconds;
    for (size_t a = 0; a < A; ++a) {
      Bands part;
      for (int b = 0; b < kNumBands; ++b) part[b] = e[b] * shares_[a * kNumBands + size_t(b)];
      out.add(delay, part, f.axes[a]);
    }
  }
}

}  // namespace dpc
