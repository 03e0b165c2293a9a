#include "engine/baked_field.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <glm/geometric.hpp>

#include "common/spherical_harmonics.h"
#include "engine/sh_energy_response.h"

namespace dpc {

size_t BakedField::bytes() const {
  return (late.size() + sh.size() + wave.size()) * sizeof(float) + waveReached.size() +
         (probes.size() + sources.size()) * sizeof(glm::vec3);
}

void fillUniformDirections(BakedField& f) {
  const size_t rows = f.probes.size() * f.sources.size() * f.directionalBins();
  const size_t C = f.shChannels();
  f.sh.assign(rows * C * kNumBands, 0.f);
  for (size_t r = 0; r < rows; ++r)
    std::fill_n(f.sh.begin() + std::ptrdiff_t(r * C * kNumBands), kNumBands, 1.f);  // W only
}

void removeArrivalSh(float* sh, size_t dbins, int order, double dbinSeconds, double delaySeconds,
                     const float* intensity, const glm::vec3& direction) {
  const double k = delaySeconds * (1.0 / dbinSeconds);  // as ShEnergyResponse::add bins it
  if (!(k >= 0.0) || k >= double(dbins)) return;
  float* row = sh + size_t(k) * size_t(ambisonicChannels(order)) * kNumBands;
  Bands e;
  for (int b = 0; b < kNumBands; ++b) e[b] = intensity[b];
  addShEnergy(order, ListenerFrame{}, direction, e, -1.f, row);
  for (int b = 0; b < kNumBands; ++b) row[b] = std::max(0.f, row[b]);
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
  blend_.resize(field_->shChannels() * kNumBands);
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

void BakeInterpolator::directionBasis(const DirectionalEnergyResponse& out) const {
  const size_t K = out.directionCount(), C = field_->shChannels();
  basis_.resize(K * C);  // allocates only when K grows
  shares_.resize(K * kNumBands);
  std::array<float, ambisonicChannels(kMaxAmbisonicOrder)> y{};
  const ListenerFrame bakeFrame;  // the bake's directions: a listener at yaw 0, pitch 0
  for (size_t k = 0; k < K; ++k) {
    const glm::vec3 a = bakeFrame.toListener(out.toWorld(out.direction(k)));
    const float dir[3] = {a.x, a.y, a.z};
    sphericalHarmonicsSn3d(field_->shOrder, dir, y);
    for (size_t c = 0; c < C; ++c) {
      const int n = int(std::sqrt(double(c)));  // ACN c = n^2 + n + m
      basis_[k * C + c] = float(2 * n + 1) * y[c];
    }
  }
}

void BakeInterpolator::directionShares(size_t source, size_t j, size_t K) const {
  const BakedField& f = *field_;
  const size_t C = f.shChannels(), D = f.directionalBins();
  std::fill(blend_.begin(), blend_.end(), 0.f);
  for (const ProbeWeight& w : weights_) {
    const float* row = f.sh.data() + ((w.probe * f.sources.size() + source) * D + j) * C * kNumBands;
    for (size_t i = 0; i < C * kNumBands; ++i) blend_[i] += w.weight * row[i];
  }
  for (int b = 0; b < kNumBands; ++b) {
    float sum = 0.f;
    for (size_t k = 0; k < K; ++k) {
      float density = 0.f;
      for (size_t c = 0; c < C; ++c) density += basis_[k * C + c] * blend_[c * kNumBands + size_t(b)];
      shares_[k * kNumBands + size_t(b)] = std::max(0.f, density);
      sum += shares_[k * kNumBands + size_t(b)];
    }
    for (size_t k = 0; k < K; ++k)
      shares_[k * kNumBands + size_t(b)] =
          sum > 0.f ? shares_[k * kNumBands + size_t(b)] / sum : 1.f / float(K);
  }
}

void BakeInterpolator::directional(size_t source, DirectionalEnergyResponse& out) const {
  out.clear();
  const BakedField& f = *field_;
  const size_t K = out.directionCount();
  directionBasis(out);
  size_t currentBin = size_t(-1);
  for (size_t k = 0; k < f.bins; ++k) {
    Bands e;
    for (const ProbeWeight& w : weights_)
      for (int b = 0; b < kNumBands; ++b)
        e[b] += w.weight * lateRow(w.probe, source)[k * kNumBands + size_t(b)];
    if (e.v == Bands().v) continue;
    if (k / f.directionalBinFactor != currentBin) {
      currentBin = k / f.directionalBinFactor;
      directionShares(source, currentBin, K);
    }
    const double delay = (double(k) + 0.5) * f.binSeconds;
    for (size_t d = 0; d < K; ++d) {
      Bands part;
      for (int b = 0; b < kNumBands; ++b) part[b] = e[b] * shares_[d * kNumBands + size_t(b)];
      out.response(d).add(delay, part);
    }
  }
}

}  // namespace dpc
